// SPDX-License-Identifier: AGPL-3.0-or-later
// Violations: TetGen, CGAL, GLM and a module header in the runtime.
#include <aggrelod/fixture_runtime.h>
#include <tetgen.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <glm/vec3.hpp>
#include "aggrelod/fixture_module.h"
