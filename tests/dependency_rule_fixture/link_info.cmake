# SPDX-License-Identifier: AGPL-3.0-or-later
# Link interfaces as tests/CMakeLists.txt writes them (dependency_rule_links.cmake), for a
# planning target that links what it may (the runtime's collision part, OMPL) and two things
# it may not (CGAL, the module), and a samples target that links the module (allowed) and the
# bake's I/O library (not allowed: bake/ links the samples).
list(APPEND TARGETS_planning fixture_planning)
set("LINKS_fixture_planning" "aggrelod_runtime_collision;/usr/lib/x86_64-linux-gnu/libompl.so;CGAL::CGAL;aggrelod::module")
list(APPEND TARGETS_samples fixture_samples)
set("LINKS_fixture_samples" "aggrelod::module;aggrelod_io")
