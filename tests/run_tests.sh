#!/usr/bin/env bash
# SPDX-License-Identifier: AGPL-3.0-or-later
# aggrelod test run: install the dependencies, build everything (Release, tests and the
# AddressSanitizer copy of the CLI on) into build/, then run the whole CTest suite.
# Exit status: that of ctest. Works from any directory.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."

bash .ci/install-deps.sh

cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DAGGRELOD_BUILD_TESTS=ON -DAGGRELOD_ASAN=ON
cmake --build build -j2

set +e
ctest --test-dir build --output-on-failure -j2
status=$?
set -e
exit "$status"
