#!/usr/bin/env bash
# SPDX-License-Identifier: AGPL-3.0-or-later
# The libFuzzer targets of tests/fuzz, for CTest (tests/CMakeLists.txt):
#   fuzz.sh build DIR SOURCE_DIR MODULE_LIBRARY CLANGXX   configure and build them with clang++
#   fuzz.sh seeds DIR MAKE_SAMPLE CLI MAKE_SYNTHETIC DATA  seed corpora from the samples, and
#                                                          2,000 mutants per reader (mutate.py)
#   fuzz.sh run DIR TARGET SECONDS                         fuzz TARGET (gltf, geo, runtime)
# A run first executes every mutant of its reader once (a call of its own, -runs=0), then
# fuzzes a fresh copy of the seeds for SECONDS (AGGRELOD_FUZZ_SECONDS overrides), both with a
# 2 GB memory limit; its exit status is non-zero on any finding (crash, sanitizer report, an
# input running over 30 s, an allocation over the limit, a file left in its temporary folder; ASan is not told to return null for a
# request it refuses, so that is a finding too). Findings are kept in DIR/findings/TARGET.
set -euo pipefail
mode=$1
dir=$2
case "$mode" in
  build)
    source_dir=$3 module=$4 clangxx=$5
    if ! command -v "$clangxx" >/dev/null 2>&1; then
      echo "fuzz: $clangxx not found (clang comes from .ci/install-deps.sh)" >&2
      exit 1
    fi
    cmake -S "$source_dir/tests/fuzz" -B "$dir/build" -DCMAKE_CXX_COMPILER="$clangxx" \
      -DCMAKE_BUILD_TYPE=RelWithDebInfo -DAGGRELOD_SOURCE_DIR="$source_dir" -DAGGRELOD_MODULE_LIBRARY="$module" >/dev/null
    cmake --build "$dir/build" -j2
    ;;
  seeds)
    make_sample=$3 cli=$4 make_synthetic=$5 data=$6
    rm -rf "$dir/seeds"
    mkdir -p "$dir/seeds/gltf" "$dir/seeds/geo" "$dir/seeds/runtime" "$dir/scratch"
    "$make_sample" two_cubes -o "$dir/seeds/gltf/two_cubes.glb"
    "$make_sample" spheres15 --seed 1 -o "$dir/seeds/gltf/spheres15.glb"
    "$cli" bake "$dir/seeds/gltf/two_cubes.glb" -o "$dir/scratch/two_cubes" --levels 3 -q
    cp "$dir/scratch/two_cubes/levels.glb" "$dir/seeds/gltf/levels.glb"
    cp "$dir/scratch/two_cubes/proxies.glb" "$dir/seeds/gltf/proxies.glb"
    cp "$dir/scratch/two_cubes/scene.aglod" "$dir/seeds/runtime/two_cubes.aglod"
    "$make_synthetic" "$dir/seeds/runtime/city40.aglod" 40 1 >/dev/null
    # A .gltf text with an embedded buffer (one triangle) and a node hierarchy.
    cat > "$dir/seeds/gltf/triangle.gltf" <<'GLTF'
{"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0]}],
 "nodes":[{"name":"root","children":[1],"translation":[1,0,0]},{"name":"tri","mesh":0,"scale":[2,2,2],"extras":{"a":[1,{"b":2}]}}],
 "meshes":[{"primitives":[{"attributes":{"POSITION":0},"indices":1}]}],
 "accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]},
              {"bufferView":1,"componentType":5123,"count":3,"type":"SCALAR"}],
 "bufferViews":[{"buffer":0,"byteLength":36},{"buffer":0,"byteOffset":36,"byteLength":6}],
 "buffers":[{"byteLength":42,"uri":"data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAAAAABAAIA"}]}
GLTF
    # Two open boxes (no top face) sharing one mesh: open sheets, thickened into shells.
    cat > "$dir/seeds/gltf/open_boxes.gltf" <<'GLTF'
{"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0,1]}],
 "nodes":[{"name":"a","mesh":0},{"name":"b","mesh":0,"translation":[5,0,0]}],
 "meshes":[{"name":"open_box","primitives":[{"attributes":{"POSITION":0},"indices":1}]}],
 "accessors":[{"bufferView":0,"componentType":5126,"count":8,"type":"VEC3","min":[0,0,0],"max":[2,1,1.5]},
              {"bufferView":1,"componentType":5123,"count":30,"type":"SCALAR"}],
 "bufferViews":[{"buffer":0,"byteLength":96},{"buffer":0,"byteOffset":96,"byteLength":60}],
 "buffers":[{"byteLength":156,"uri":"data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAAAAQAAAAAAAAAAAAAAAQAAAgD8AAAAAAAAAAAAAgD8AAAAAAAAAAAAAAAAAAMA/AAAAQAAAAAAAAMA/AAAAQAAAgD8AAMA/AAAAAAAAgD8AAMA/AAADAAIAAAACAAEAAAABAAUAAAAFAAQAAQACAAYAAQAGAAUAAgADAAcAAgAHAAYAAwAAAAQAAwAEAAcA"}]}
GLTF
    printf 'POLYGON ((0 0, 10 0, 10 10, 0 10, 0 0), (2 2, 4 2, 4 4, 2 4, 2 2))\nMULTIPOLYGON (((20 0, 30 0, 30 5, 20 0)), ((40 0, 41 0, 41 1, 40 0)))\n' \
      > "$dir/seeds/geo/two.wkt"
    printf '{"type":"FeatureCollection","features":[{"type":"Feature","properties":{"name":"a"},"geometry":{"type":"Polygon","coordinates":[[[0,0],[1,0],[1,1],[0,0]]]}},{"type":"Feature","geometry":{"type":"MultiPolygon","coordinates":[[[[2,2],[3,2],[3,3],[2,2]]]]}}]}\n' \
      > "$dir/seeds/geo/two.geojson"
    for f in "$data/2d/nc_counties.wkt" "$data/2d/london_boroughs.geojson"; do
      if [ -f "$f" ]; then head -c 20000 "$f" > "$dir/seeds/geo/$(basename "$f")"; fi
    done
    rm -rf "$dir/mutants"
    python3 "$(dirname "${BASH_SOURCE[0]}")/mutate.py" "$dir/seeds" "$dir/mutants" 2000
    ;;
  run)
    target=$3 seconds=${AGGRELOD_FUZZ_SECONDS:-$4}
    corpus="$dir/corpus/$target" findings="$dir/findings/$target"
    rm -rf "$corpus"
    mkdir -p "$corpus" "$findings"
    cp "$dir/seeds/$target"/* "$corpus/"
    export ASAN_OPTIONS=detect_leaks=0
    export UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1
    cd "$findings"
    # A private temporary folder: whatever a target leaves behind in it is a finding too.
    export TMPDIR="$dir/tmp/$target"
    rm -rf "$TMPDIR"
    mkdir -p "$TMPDIR"
    limits=(-rss_limit_mb=2048 -malloc_limit_mb=2048 -timeout=30 -max_len=1048576 -artifact_prefix="$findings/")
    # Every mutant once, outside the timed run.
    "$dir/build/fuzz_$target" -runs=0 "${limits[@]}" "$dir/mutants/$target"
    "$dir/build/fuzz_$target" -max_total_time="$seconds" -print_final_stats=1 "${limits[@]}" "$corpus"
    if [ -n "$(ls -A "$TMPDIR")" ]; then
      echo "fuzz: fuzz_$target left files in its temporary folder:" >&2
      ls -A "$TMPDIR" >&2
      exit 1
    fi
    ;;
  *)
    echo "usage: fuzz.sh build|seeds|run ..." >&2
    exit 2
    ;;
esac
