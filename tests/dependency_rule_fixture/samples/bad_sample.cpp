// SPDX-License-Identifier: AGPL-3.0-or-later
// Allowed: the module's public headers and the standard library.
#include <aggrelod/fixture_module.h>
#include <vector>
// Violations: a bake header and tinygltf in samples/ (bake/ uses the samples: a cycle).
#include "fixture_bake.h"
#include <tiny_gltf.h>
