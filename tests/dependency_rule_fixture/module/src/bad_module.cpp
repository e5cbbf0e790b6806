// SPDX-License-Identifier: AGPL-3.0-or-later
// Violations: tinygltf and a runtime header in the module (the contract header is allowed).
#include <aggrelod/fixture_module.h>
#include <tiny_gltf.h>
#include <aggrelod/fixture_runtime.h>
#include <aggrelod/runtime_build.h>
