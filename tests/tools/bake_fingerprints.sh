#!/usr/bin/env bash
# SPDX-License-Identifier: AGPL-3.0-or-later
# Prints one line per output file of a bake, with its SHA-256: every sample scene and every
# real scene of ../shared/data/3d as given (no options), with --threads 1. Two builds that
# print the same lines write identical outputs; use it around a change meant to keep them.
#   tests/tools/bake_fingerprints.sh BUILD_DIR [WORK_DIR]
# The stats JSON is fingerprinted after parsing (same keys and values; formatting may differ)
# and without its timings.
set -euo pipefail
build=${1:?usage: bake_fingerprints.sh BUILD_DIR [WORK_DIR]}
work=${2:-$(mktemp -d)}
here=$(cd "$(dirname "$0")/../.." && pwd)
data="$here/../shared/data/3d"
cli="$build/bake/aggrelod"
make_sample="$build/samples/aggrelod_make_sample"
mkdir -p "$work"

stats_hash() {
  python3 - "$1" <<'PY'
import hashlib, json, sys
s = json.load(open(sys.argv[1]))
s.pop("timings", None)
print(hashlib.sha256(json.dumps(s, sort_keys=True).encode()).hexdigest())
PY
}

bake_one() {  # label input
  local label=$1 input=$2 out="$work/$1"
  rm -rf "$out"
  if ! "$cli" bake "$input" -o "$out" --quiet --threads 1 --stats "$out/stats.json" >"$work/$label.log" 2>&1; then
    echo "$label: bake failed (exit $?; see $work/$label.log)"
    return
  fi
  for f in levels.glb proxies.glb scene.aglod; do
    echo "$label/$f $(sha256sum "$out/$f" | cut -c1-16)"
  done
  echo "$label/stats.json $(stats_hash "$out/stats.json" | cut -c1-16)"
}

for name in two_cubes slabs spheres15 chess forest village; do
  "$make_sample" "$name" -o "$work/$name.glb" >/dev/null
  bake_one "$name" "$work/$name.glb"
done
"$make_sample" random -o "$work/random400.glb" --objects 400 --triangles 60000 >/dev/null
bake_one random400 "$work/random400.glb"
if [ -d "$data" ]; then
  while IFS= read -r scene; do
    bake_one "real_$(basename "$scene" | sed 's/\.[^.]*$//')" "$scene"
  done < <(find "$data" -name '*.glb' -o -name '*.gltf' | LC_ALL=C sort)
fi
