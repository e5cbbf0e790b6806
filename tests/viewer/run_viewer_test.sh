#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# The viewer test (CTest viewer_headless_flight): flies samples/viewer's camera path over a baked
# scene headless (its own Xvfb + Mesa llvmpipe), has bench_lod_budget select the cut for the same
# cameras, and checks the viewer's draw calls, triangles and screenshots against it
# (check_viewer_run). Run as
#   run_viewer_test.sh VIEWER BENCH CHECKER SCENE.aglod OUT_DIR [viewer options...]
# Exit status: 0 passed, 1 failed, 77 skipped (Xvfb is not installed, or no OpenGL 3.3 context:
# the message says which package is missing).
set -uo pipefail
if [ "$#" -lt 5 ]; then
  echo "usage: run_viewer_test.sh VIEWER BENCH CHECKER SCENE.aglod OUT_DIR [viewer options...]" >&2
  exit 2
fi
viewer=$1 bench=$2 checker=$3 scene=$4 out=$5
shift 5

rm -rf "$out"
mkdir -p "$out"

# Mesa's software rasteriser (llvmpipe), two threads: the machine's other jobs share the cores.
export LIBGL_ALWAYS_SOFTWARE=1 LP_NUM_THREADS=2
# A private Xvfb: it picks a free display itself (-displayfd) and writes its number when it is
# ready, so parallel runs cannot collide; it is stopped on exit.
if ! command -v Xvfb >/dev/null 2>&1; then
  echo "viewer test: SKIPPED: no X server: install xvfb and libgl1-mesa-dri (.ci/install-deps.sh)"
  exit 77
fi
Xvfb -displayfd 3 -screen 0 1280x1024x24 -nolisten tcp 3>"$out/xvfb.display" 2>"$out/xvfb.log" &
xvfb_pid=$!
trap 'kill "$xvfb_pid" 2>/dev/null; wait "$xvfb_pid" 2>/dev/null' EXIT
for _ in $(seq 100); do
  grep -q . "$out/xvfb.display" 2>/dev/null && break
  kill -0 "$xvfb_pid" 2>/dev/null || break
  sleep 0.1
done
display=$(head -n1 "$out/xvfb.display" 2>/dev/null)
if [ -z "$display" ]; then
  echo "viewer test: FAILED: Xvfb did not start:"
  cat "$out/xvfb.log"
  exit 1
fi
export DISPLAY=":$display"
echo "viewer test: Xvfb on display $DISPLAY"

start=$(date +%s.%N)
"$viewer" "$scene" --out "$out/frames" --hidden --compare-originals "$@"
status=$?
if [ "$status" -eq 77 ]; then
  echo "viewer test: SKIPPED: no OpenGL 3.3 context (see the message above)"
  exit 77
fi
if [ "$status" -ne 0 ]; then
  echo "viewer test: FAILED: aglod_viewer exited with status $status"
  exit 1
fi
end=$(date +%s.%N)
echo "viewer run: $(awk -v a="$start" -v b="$end" 'BEGIN { printf "%.2f", b - a }') s"

if ! "$bench" --cut-for "$scene" --cameras "$out/frames/frames.csv" > "$out/bench_cuts.csv"; then
  echo "viewer test: FAILED: bench_lod_budget --cut-for failed"
  exit 1
fi
"$checker" "$out/frames" "$out/bench_cuts.csv"
