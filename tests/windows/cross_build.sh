#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# The runtime for Windows: cross-compiled with Debian's mingw-w64 toolchain from a
# runtime-only configure (no collision part: there is no Embree for mingw), with its unit tests
# (tests/runtime_only), and those tests run under wine.
#   cross_build.sh build SOURCE_DIR WORK_DIR [CMAKE]   CTest runtime_windows_cross_build
#   cross_build.sh run   SOURCE_DIR WORK_DIR           CTest runtime_windows_unit_tests_wine
# Exit 77 (CTest: skipped) with a message when the toolchain, respectively wine, is missing;
# 1 on any failure.
set -euo pipefail

mode="$1"
src="$(cd "$2" && pwd)"
work="$3"
cmake="${4:-cmake}"
triplet=x86_64-w64-mingw32
build="$work/build"
exe="$build/tests/runtime_only/aggrelod_runtime_unit_tests.exe"

fail() { echo "windows cross build: FAILED: $*" >&2; exit 1; }

if ! command -v "$triplet-g++-posix" >/dev/null 2>&1 && ! command -v "$triplet-g++" >/dev/null 2>&1; then
  echo "SKIPPED: the mingw-w64 toolchain ($triplet-g++) is not installed (Debian: mingw-w64, see" \
       ".ci/install-deps.sh): the runtime was not cross-built for Windows"
  exit 77
fi

case "$mode" in
build)
  gtest_src=/usr/src/googletest
  [ -f "$gtest_src/CMakeLists.txt" ] || fail "$gtest_src is missing (Debian: libgtest-dev)"
  rm -rf "$work"
  mkdir -p "$work"
  "$cmake" -S "$src" -B "$build" -DCMAKE_TOOLCHAIN_FILE="$src/cmake/toolchains/mingw-w64-x86_64.cmake" \
    -DCMAKE_BUILD_TYPE=Release -DAGGRELOD_RUNTIME_ONLY=ON -DAGGRELOD_GTEST_SOURCE_DIR="$gtest_src" \
    | tee "$work/configure.log"
  grep -q "collision part (aggrelod::runtime_collision) is skipped" "$work/configure.log" ||
    fail "expected the collision part to be skipped (no Embree for mingw)"
  "$cmake" --build "$build" -j"${AGGRELOD_CROSS_JOBS:-2}" --target aggrelod_runtime aggrelod_runtime_unit_tests
  [ -f "$exe" ] || fail "$exe was not built"
  # A Windows PE executable ("MZ" header) that needs no DLL beyond the system's.
  [ "$(head -c 2 "$exe")" = "MZ" ] || fail "$exe is not a Windows executable"
  dlls="$("$triplet-objdump" -p "$exe" | sed -n 's/^[[:space:]]*DLL Name: //p' | tr '\n' ' ')"
  echo "DLLs imported by $(basename "$exe"): $dlls"
  for dll in $dlls; do
    case "$(echo "$dll" | tr '[:upper:]' '[:lower:]')" in
      kernel32.dll|msvcrt.dll|ucrtbase.dll|api-ms-win-*|advapi32.dll|user32.dll|shell32.dll|ws2_32.dll) ;;
      *) fail "$(basename "$exe") needs $dll at run time (link it statically)" ;;
    esac
  done
  echo "windows cross build: PASSED ($(basename "$exe"), $(stat -c %s "$exe") bytes)"
  ;;
run)
  wine=""
  for w in wine wine64; do
    if command -v "$w" >/dev/null 2>&1; then wine="$w"; break; fi
  done
  if [ -z "$wine" ]; then
    echo "SKIPPED: wine is not installed (Debian: wine, wine64): the Windows unit tests were built but not run"
    exit 77
  fi
  [ -f "$exe" ] || fail "$exe is missing (runtime_windows_cross_build must run first)"
  # The prefix lives beside WORK_DIR, so that a new build keeps it (making one takes ~10 s).
  export WINEPREFIX="$(dirname "$work")/wineprefix" WINEDEBUG=-all WINEDLLOVERRIDES="mscoree,mshtml="
  run_dir="$work/run"
  rm -rf "$run_dir"
  mkdir -p "$run_dir"
  cd "$run_dir"
  set +e
  "$wine" "$exe" 2>&1 | tr -d '\r' | tee "$work/wine.log"  # the .exe writes CRLF
  status=${PIPESTATUS[0]}
  set -e
  # Stop this prefix's wine server (started by the run above) so that nothing outlives the test.
  wineserver="$(command -v wineserver || echo /usr/lib/wine/wineserver)"
  "$wineserver" -k >/dev/null 2>&1 || true
  [ "$status" -eq 0 ] || fail "the unit tests exited with $status under $wine"
  grep -q '^\[  PASSED  \] [0-9]* tests\?\.$' "$work/wine.log" || fail "no GoogleTest PASSED line"
  if grep -q '^\[  FAILED  \]' "$work/wine.log"; then fail "failed tests above"; fi
  echo "windows unit tests under $wine: PASSED"
  ;;
*)
  fail "unknown mode $mode (build or run)"
  ;;
esac
