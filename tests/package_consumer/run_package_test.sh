#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# CTest runtime_package_consumer: builds the runtime alone (AGGRELOD_RUNTIME_ONLY=ON), installs
# it into a fresh prefix, then builds tests/package_consumer against the installed CMake
# package (find_package(aggrelod CONFIG REQUIRED COMPONENTS runtime collision)) and runs its
# programs, and compiles the two C programs again with nothing but pkg-config's flags.
#   run_package_test.sh SOURCE_DIR WORK_DIR [CMAKE]
# Fails (exit 1) on any broken step; prints "package test: PASSED" at the end.
set -euo pipefail

src="$(cd "$1" && pwd)"
work="$2"
cmake="${3:-cmake}"
consumer="$src/tests/package_consumer"
jobs="${AGGRELOD_PACKAGE_TEST_JOBS:-2}"

rm -rf "$work"
mkdir -p "$work"
work="$(cd "$work" && pwd)"
prefix="$work/prefix"

step() { echo; echo "=== package test: $*"; }
fail() { echo "package test: FAILED: $*" >&2; exit 1; }
trap 'echo "package test: FAILED: the command on line $LINENO exited with $?" >&2' ERR

step "configure a runtime-only build"
"$cmake" -S "$src" -B "$work/runtime-build" -DAGGRELOD_RUNTIME_ONLY=ON -DAGGRELOD_BUILD_TESTS=OFF \
  -DCMAKE_BUILD_TYPE=Release | tee "$work/runtime-configure.log"
# The runtime-only configure must not even look for the bake side's dependencies: no cache
# entry of their lookups may exist.
if grep -E '^(CGAL|TinyGLTF|CLI11|glm|meshoptimizer|ompl|OMPL|GTest|GEOS|Threads)_DIR:|^TETGEN_|^STB_|^PKG_CONFIG_EXECUTABLE:' \
     "$work/runtime-build/CMakeCache.txt"; then
  fail "the runtime-only configure looked for bake dependencies (cache entries above)"
fi
grep -q '^embree_DIR:PATH=.*[^-]NOTFOUND$\|^embree_DIR:PATH=/' "$work/runtime-build/CMakeCache.txt" ||
  fail "the runtime-only configure did not look for Embree"

step "build and install it into $prefix"
"$cmake" --build "$work/runtime-build" -j"$jobs"
"$cmake" --install "$work/runtime-build" --prefix "$prefix"
for f in include/aggrelod_runtime.h include/aggrelod/runtime_file.h include/aggrelod/selection.h \
         include/aggrelod/runtime_build.h include/aggrelod/collision.h; do
  [ -f "$prefix/$f" ] || fail "$f was not installed"
done
grep -q "MIT License" "$prefix/share/doc/aggrelod-runtime/LICENSE" || fail "the runtime's LICENSE was not installed"
config="$(find "$prefix" -name aggrelod-config.cmake)"
[ -n "$config" ] || fail "no aggrelod-config.cmake installed"
pcdir="$(dirname "$(find "$prefix" -name aggrelod-runtime.pc)")"
[ -f "$pcdir/aggrelod-runtime-collision.pc" ] || fail "no aggrelod-runtime-collision.pc installed"

step "configure and build the consumer project against the installed package"
# Only the prefix: the user package registry and the source tree are out of reach.
"$cmake" -S "$consumer" -B "$work/consumer-build" -DCMAKE_BUILD_TYPE=Release \
  -DCMAKE_PREFIX_PATH="$prefix" -DCMAKE_FIND_USE_PACKAGE_REGISTRY=OFF
grep -q "^aggrelod_DIR:PATH=$(dirname "$config")\$" "$work/consumer-build/CMakeCache.txt" ||
  fail "the consumer did not take the package from $prefix"
"$cmake" --build "$work/consumer-build" -j"$jobs"

step "run the consumer's programs"
"$work/consumer-build/write_and_select" "$work/scene.aglod"
"$work/consumer-build/select_c" "$work/scene.aglod"
"$work/consumer-build/raycast_c" "$work/scene.aglod"

step "pkg-config: compile the C programs with pkg-config --cflags --libs alone"
export PKG_CONFIG_PATH="$pcdir"
command -v pkg-config >/dev/null || fail "pkg-config not found (Debian: pkg-config)"
cc="${CC:-cc}"
flags="$(pkg-config --cflags --libs aggrelod-runtime)"
echo "aggrelod-runtime: $flags"
case "$flags" in *"-I$prefix/"*) ;; *) fail "pkg-config --cflags does not point into $prefix" ;; esac
# shellcheck disable=SC2086
"$cc" -std=c99 -Wall -Wextra -Werror "$consumer/select.c" -o "$work/select_pkgconfig" $flags
"$work/select_pkgconfig" "$work/scene.aglod"
flags="$(pkg-config --cflags --libs aggrelod-runtime-collision)"
echo "aggrelod-runtime-collision: $flags"
# shellcheck disable=SC2086
"$cc" -std=c99 -Wall -Wextra -Werror "$consumer/raycast.c" -o "$work/raycast_pkgconfig" $flags -lm
"$work/raycast_pkgconfig" "$work/scene.aglod"
# The engine-integration sample as a user would build it from the installed tree.
# shellcheck disable=SC2086
"$cc" -std=c99 -Wall -Wextra -Werror "$src/samples/hello_runtime.c" -o "$work/hello_runtime_pkgconfig" $flags -lm
"$work/hello_runtime_pkgconfig" "$work/scene.aglod" | tee "$work/hello_runtime.log"
grep -q 'ray against level 0 *: hit at' "$work/hello_runtime.log" || fail "hello_runtime: no hit on level 0"
[ "$(pkg-config --modversion aggrelod-runtime)" = "$(pkg-config --modversion aggrelod-runtime-collision)" ] ||
  fail "the two .pc files disagree on the version"

echo
echo "package test: PASSED"
