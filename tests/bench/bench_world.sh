#!/usr/bin/env bash
# SPDX-License-Identifier: AGPL-3.0-or-later
# Huge-world benchmark (docs/benchmarks.md, "Worlds"): for each world size, the generated open
# world (aggrelod_make_sample world), its whole bake as one piece, wall seconds and peak memory
# (GNU time), and the bake's own stage seconds from its stats: TetGen's share and the proxies'.
#   tests/bench/bench_world.sh BUILD_DIR [WORK_DIR] [SIZES=4000] [THREADS=2] [SEED=1]
# Sizes are comma-separated object counts (at most 65536). Prints a Markdown table.
set -euo pipefail
build=${1:?usage: bench_world.sh BUILD_DIR [WORK_DIR] [SIZES] [THREADS] [SEED]}
work=${2:-$(mktemp -d)}
sizes=${3:-4000}
threads=${4:-2}
seed=${5:-1}
cli="$build/bake/aggrelod"
make_sample="$build/samples/aggrelod_make_sample"
mkdir -p "$work"
if [ ! -x /usr/bin/time ]; then echo "bench_world: needs GNU time (/usr/bin/time, Debian package time)" >&2; exit 2; fi

echo "| objects | triangles | bake s | peak MiB | tetrahedralize s | levels s | proxies s | bake / TetGen |"
echo "|---:|---:|---:|---:|---:|---:|---:|---:|"
IFS=, read -ra counts <<< "$sizes"
for n in "${counts[@]}"; do
  glb="$work/world$n.glb" out="$work/world$n"
  summary=$("$make_sample" world --objects "$n" --seed "$seed" -o "$glb")
  triangles=$(sed -n 's/.* objects, \([0-9]*\) triangles.*/\1/p' <<< "$summary")
  rm -rf "$out"
  /usr/bin/time -f "%e %M" -o "$work/time$n.txt" \
    "$cli" bake "$glb" -o "$out" --threads "$threads" --quiet --stats "$work/stats$n.json" > "$work/bake$n.log" 2>&1 ||
    { echo "| $n | $triangles | bake failed: see $work/bake$n.log | | | | | |"; continue; }
  read -r seconds kib < "$work/time$n.txt"
  python3 - "$n" "$triangles" "$seconds" "$kib" "$work/stats$n.json" <<'PY'
import json, sys
n, triangles, seconds, kib, stats = sys.argv[1:]
t = json.load(open(stats))["timings"]
tet = t.get("tetrahedralize", 0.0)
ratio = float(seconds) / tet if tet > 0 else float("nan")
print(f"| {n} | {triangles} | {float(seconds):.1f} | {int(kib) / 1024:.0f} | {tet:.1f} | "
      f"{t.get('levels', 0.0):.1f} | {t.get('proxies', 0.0):.1f} | {ratio:.1f} |")
PY
done
