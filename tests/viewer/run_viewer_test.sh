#!/usr/bin/env bash
# The viewer test (CTest viewer_headless_flight): flies samples/viewer's camera path over a baked
# scene headless (Xvfb + Mesa llvmpipe), has bench_lod_budget select the cut for the same
# cameras, and checks the viewer's draw calls, triangles and screenshots against it
# (check_viewer_run). Run as
#   run_viewer_test.sh VIEWER BENCH CHECKER SCENE.aglod OUT_DIR [viewer options...]
# Exit status: 0 passed, 1 failed, 77 skipped (no X server can be started, or no OpenGL 3.3
# context: the message says which package is missing).
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
if command -v xvfb-run >/dev/null 2>&1; then
  run=(xvfb-run -a -s "-screen 0 1280x1024x24 -nolisten tcp" "$viewer")
elif [ -n "${DISPLAY:-}" ]; then
  run=("$viewer")
else
  echo "viewer test: SKIPPED: no X server: install xvfb (xvfb-run) and libgl1-mesa-dri (.ci/install-deps.sh)"
  exit 77
fi

start=$(date +%s.%N)
"${run[@]}" "$scene" --out "$out/frames" --hidden --compare-originals "$@"
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
