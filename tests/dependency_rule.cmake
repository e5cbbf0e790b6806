# SPDX-License-Identifier: AGPL-3.0-or-later
# Checks the dependency rule of docs/design.md §1. Run as
#   cmake -DSOURCE_DIR=<repo root> [-DLINK_INFO=<generated file>] -P dependency_rule.cmake
#
# - no file under runtime/ includes TetGen, CGAL, tinygltf, nlohmann-json, meshoptimizer, GEOS, GLM or any
#   header of module/;
# - no file under module/ includes tinygltf or any header of runtime/ but the contract,
#   aggrelod/runtime_build.h (standard library only: the module emits it, the runtime's writer
#   consumes it);
# - no file under planning/ includes TetGen, CGAL, GMP/MPFR, tinygltf, meshoptimizer, GEOS,
#   GLM, CLI11, stb or any header of module/, bake/ or samples/ (it may use the runtime with
#   its collision part, OMPL and the standard library);
# - no file under samples/ includes tinygltf, CLI11 or any header of bake/ (bake/ uses the
#   samples' generators; the way back would make a cycle);
# - (when samples/viewer exists) no file of the OpenGL viewer includes anything but the runtime's
#   C API among the project's headers: no header of module/ or bake/, no C++ runtime header
#   (aggrelod/...), none of the bake-side libraries or Embree;
# - (with LINK_INFO, written by tests/CMakeLists.txt at generate time) no target defined under
#   runtime/ links TetGen, CGAL, GMP/MPFR, tinygltf, meshoptimizer, GEOS, GLM or the module, no
#   target under module/ links tinygltf or the runtime, no target under planning/ links
#   TetGen, CGAL, GMP/MPFR, tinygltf, meshoptimizer, GEOS, GLM, CLI11, stb, the module, the
#   bake's libraries or executable or the samples' library, and the viewer (TARGETS_viewer)
#   links none of the bake-side libraries, the module, the bake's or the samples' libraries,
#   or Embree; no target under samples/ links the bake's libraries or executables, CLI11 or
#   tinygltf.
# Prints every violation and fails (FATAL_ERROR) when there is one.
cmake_minimum_required(VERSION 3.22)

if(NOT SOURCE_DIR)
  message(FATAL_ERROR "dependency_rule: pass -DSOURCE_DIR=<repository root>")
endif()

set(_source_globs *.h *.hh *.hpp *.hxx *.inl *.ipp *.c *.cc *.cpp *.cxx)
set(violations 0)

# Headers of a part, as they could be named in an #include: path relative to the include
# directory (e.g. aggrelod/aggregate3d.h) and bare file name.
function(collect_header_names part out_var)
  set(names "")
  foreach(pattern *.h *.hh *.hpp *.hxx *.inl)
    file(GLOB_RECURSE headers "${SOURCE_DIR}/${part}/${pattern}")
    foreach(h IN LISTS headers)
      get_filename_component(base "${h}" NAME)
      list(APPEND names "${base}")
      file(RELATIVE_PATH rel "${SOURCE_DIR}/${part}/include" "${h}")
      if(NOT rel MATCHES "^\\.\\.")
        list(APPEND names "${rel}")
      endif()
    endforeach()
  endforeach()
  list(REMOVE_DUPLICATES names)
  set(${out_var} "${names}" PARENT_SCOPE)
endfunction()

# Checks every #include of every source file under SOURCE_DIR/<part>.
#   forbidden_regex: included names that are not allowed
#   forbidden_names: exact included names (or names ending in /<name>) that are not allowed
function(check_includes part forbidden_regex forbidden_names)
  set(count 0)
  set(files "")
  foreach(pattern IN LISTS _source_globs)
    file(GLOB_RECURSE found "${SOURCE_DIR}/${part}/${pattern}")
    list(APPEND files ${found})
  endforeach()
  list(REMOVE_DUPLICATES files)
  list(SORT files)
  list(LENGTH files nfiles)
  foreach(f IN LISTS files)
    file(STRINGS "${f}" lines REGEX "^[ \t]*#[ \t]*include[ \t]*[<\"]")
    foreach(line IN LISTS lines)
      if(NOT line MATCHES "^[ \t]*#[ \t]*include[ \t]*[<\"]([^>\"]+)[>\"]")
        continue()
      endif()
      set(name "${CMAKE_MATCH_1}")
      set(bad FALSE)
      if(name MATCHES "${forbidden_regex}")
        set(bad TRUE)
      endif()
      get_filename_component(base "${name}" NAME)
      foreach(n IN LISTS forbidden_names)
        if(name STREQUAL n OR (NOT n MATCHES "/" AND base STREQUAL n))
          set(bad TRUE)
        endif()
      endforeach()
      if(bad)
        file(RELATIVE_PATH rel "${SOURCE_DIR}" "${f}")
        message("VIOLATION: ${rel} includes <${name}> (not allowed in ${part}/)")
        math(EXPR count "${count} + 1")
      endif()
    endforeach()
  endforeach()
  message("dependency_rule: ${part}/: ${nfiles} source files checked, ${count} forbidden includes")
  math(EXPR total "${violations} + ${count}")
  set(violations ${total} PARENT_SCOPE)
endfunction()

collect_header_names(module module_headers)
collect_header_names(runtime runtime_headers)
# A header that exists in both parts under the same name cannot tell them apart: leave it out.
set(module_only ${module_headers})
set(runtime_only ${runtime_headers})
if(module_headers AND runtime_headers)
  list(REMOVE_ITEM module_only ${runtime_headers})
  list(REMOVE_ITEM runtime_only ${module_headers})
endif()
# The bake -> runtime contract: the one runtime header the module may include.
set(runtime_forbidden_in_module ${runtime_only})
list(REMOVE_ITEM runtime_forbidden_in_module "aggrelod/runtime_build.h" "runtime_build.h")

# Bare names of the bake's and the samples' headers (bake/*.h, samples/include/aggrelod/*.h).
set(bake_headers "")
file(GLOB _bake_headers "${SOURCE_DIR}/bake/*.h")
foreach(h IN LISTS _bake_headers)
  get_filename_component(base "${h}" NAME)
  list(APPEND bake_headers "${base}")
endforeach()
collect_header_names(samples samples_headers)

check_includes(runtime
  "(^|/)tetgen\\.h$|^CGAL/|(^|/)tiny_gltf\\.h$|(^|/)meshoptimizer\\.h$|^geos|^glm/|^nlohmann/|(^|/)module/"
  "${module_only}")
check_includes(module
  "(^|/)tiny_gltf\\.h$|(^|/)runtime/"
  "${runtime_forbidden_in_module}")
if(EXISTS "${SOURCE_DIR}/planning")
  # planning/ may use the runtime (with its collision part), OMPL and the standard library.
  # A name that is also a runtime or planning header cannot be told apart: leave it out.
  collect_header_names(planning planning_headers)
  set(_planning_forbidden_names ${module_only} ${bake_headers} ${samples_headers})
  if(_planning_forbidden_names AND (runtime_headers OR planning_headers))
    list(REMOVE_ITEM _planning_forbidden_names ${runtime_headers} ${planning_headers})
  endif()
  check_includes(planning
    "(^|/)tetgen\\.h$|^CGAL/|^gmp|^mpfr|(^|/)tiny_gltf\\.h$|(^|/)meshoptimizer\\.h$|^geos|^glm/|^CLI/|(^|/)stb_[a-z_]*\\.h$|(^|/)module/|(^|/)bake/|(^|/)samples/"
    "${_planning_forbidden_names}")
endif()
if(EXISTS "${SOURCE_DIR}/samples")
  # A name that is also a samples header cannot be told apart: leave it out.
  set(_samples_forbidden_names ${bake_headers})
  if(_samples_forbidden_names AND samples_headers)
    list(REMOVE_ITEM _samples_forbidden_names ${samples_headers})
  endif()
  check_includes(samples "(^|/)tiny_gltf\\.h$|^CLI/|(^|/)bake/" "${_samples_forbidden_names}")
endif()
if(EXISTS "${SOURCE_DIR}/samples/viewer")
  check_includes(samples/viewer
    "(^|/)tetgen\\.h$|^CGAL/|(^|/)tiny_gltf\\.h$|(^|/)meshoptimizer\\.h$|^geos|^glm/|^embree|(^|/)module/|(^|/)bake/|^aggrelod/"
    "${module_only};${bake_headers}")
endif()

if(LINK_INFO)
  if(NOT EXISTS "${LINK_INFO}")
    message(FATAL_ERROR "dependency_rule: ${LINK_INFO} is missing (re-run cmake)")
  endif()
  include("${LINK_INFO}")
  set(_forbidden_runtime "tet|cgal|gmp|mpfr|tinygltf|nlohmann|meshoptimizer|geos|glm|aggrelod_module|aggrelod::module|aggrelod_io|aggrelod_samples")
  set(_forbidden_module "tinygltf|aggrelod_runtime|aggrelod::runtime|aggrelod_io")
  set(_forbidden_planning "tet|cgal|gmp|mpfr|tinygltf|meshoptimizer|geos|glm|cli11|pkgconfig::stb|stb_image|aggrelod_module|aggrelod::module|aggrelod_io|aggrelod_render|aggrelod_samples|aggrelod::samples|^aggrelod$|^aggrelod_asan$")
  set(_forbidden_viewer "tet|cgal|gmp|mpfr|tinygltf|meshoptimizer|geos|glm|embree|aggrelod_module|aggrelod::module|aggrelod_io|aggrelod_samples|aggrelod_render|aggrelod_planning|aggrelod_runtime_collision")
  set(_forbidden_samples "tinygltf|cli11|aggrelod_io|aggrelod_render|^aggrelod$|^aggrelod_asan$|^aggrelod_make_sample$")
  foreach(part runtime module planning samples viewer)
    set(count 0)
    foreach(t IN LISTS TARGETS_${part})
      set(links "${LINKS_${t}}")
      list(REMOVE_ITEM links "")
      list(REMOVE_DUPLICATES links)
      message("dependency_rule: ${part}/ target ${t} links: ${links}")
      foreach(l IN LISTS links)
        string(TOLOWER "${l}" lower)
        if(lower MATCHES "${_forbidden_${part}}")
          message("VIOLATION: ${part}/ target ${t} links ${l}")
          math(EXPR count "${count} + 1")
        endif()
      endforeach()
    endforeach()
    math(EXPR violations "${violations} + ${count}")
  endforeach()
endif()

if(violations GREATER 0)
  message(FATAL_ERROR "dependency_rule: ${violations} violation(s) of the dependency rule (docs/design.md §1)")
endif()
message("dependency_rule: OK")
