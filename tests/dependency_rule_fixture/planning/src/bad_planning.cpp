// SPDX-License-Identifier: AGPL-3.0-or-later
// Allowed: its own header, the runtime (collision part included), OMPL, the standard library.
#include <aggrelod/fixture_planning.h>
#include <aggrelod/fixture_runtime.h>
#include <ompl/geometric/planners/prm/LazyPRM.h>
#include <vector>
// Violations: TetGen, CGAL, tinygltf, a module header and a bake header in planning/.
#include <tetgen.h>
#include <CGAL/Constrained_Delaunay_triangulation_2.h>
#include <tiny_gltf.h>
#include <aggrelod/fixture_module.h>
#include "fixture_bake.h"
