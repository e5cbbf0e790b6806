#!/usr/bin/env bash
# SPDX-License-Identifier: AGPL-3.0-or-later
# aggrelod main job: install the dependencies, build (Release) into build/, generate the
# 15-spheres sample scene (paper Fig. 9) into out/ and bake its LOD hierarchy, printing the
# level table and rendering a sheet of its levels; then run the runtime example on the baked
# file, bake and render the forest and village samples, and run the paper's 2D evaluation.
# Works from any directory.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."

bash .ci/install-deps.sh

cmake -S . -B build -DCMAKE_BUILD_TYPE=Release
cmake --build build -j2

mkdir -p out
build/samples/aggrelod_make_sample spheres15 --seed 1 -o out/spheres15.glb
mkdir -p out/spheres15
build/bake/aggrelod bake out/spheres15.glb -o out/spheres15 --stats out/spheres15/stats.json --tiles
build/bake/aggrelod render out/spheres15/scene.aglod --sheet -o out/spheres15/sheet.png


# What an engine does with the baked file: open it, fly a camera, print the cut, cast a ray.
echo
build/samples/hello_runtime out/spheres15/scene.aglod

# More sample scenes, each baked and rendered as a sheet of its levels: a forest (trunks and
# canopies), a village (houses, fences, barrels) and the chess pieces (paper Fig. 8).
for sample in forest village chess; do
  echo
  build/samples/aggrelod_make_sample "$sample" --seed 1 -o "out/$sample.glb"
  build/bake/aggrelod bake "out/$sample.glb" -o "out/$sample" --quiet
  build/bake/aggrelod render "out/$sample/scene.aglod" --sheet -o "out/$sample/sheet.png"
  build/bake/aggrelod render "out/$sample/levels.glb" --sheet -o "out/$sample/levels.png" --quiet
done

# The paper's 2D evaluation: five environments, tables and figures.
echo
build/bake/aggrelod reproduce2d -o out/reproduce2d --quiet
echo "2D evaluation (paper Fig. 4 and 6): out/reproduce2d/table.md, fig4-<environment>.png, fig6.png"

echo
echo "Wrote out/spheres15/levels.glb (one node per aggregate per level), proxies.glb (the runtime"
echo "tree as glTF), scene.aglod (the runtime file), stats.json, tiles/ (3D Tiles) and sheet.png"
echo "(a render of every level); out/forest/, out/village/ and out/chess/ hold the same for the"
echo "other samples, and levels.png (every level's exact aggregates). View the tiles with:"
echo "node samples/web/serve.mjs --tileset out/spheres15/tiles"
echo "(then open http://127.0.0.1:8080/)"
