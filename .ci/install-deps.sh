#!/usr/bin/env bash
# Installs what aggrelod needs to build and test, on Debian bookworm. Idempotent: apt runs
# only when a package is missing, npm only when tests/validator/node_modules or
# samples/web/node_modules is missing or older than its package-lock.json. Runs as root, or
# through sudo otherwise.
set -euo pipefail

repo_root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"

if [ "$(id -u)" -eq 0 ]; then
  SUDO=()
else
  SUDO=(sudo)
fi

packages=(
  build-essential cmake pkg-config ccache git
  libglm-dev libtinygltf-dev libembree-dev libtet1.5-dev
  libcgal-dev libgmp-dev libmpfr-dev libmeshoptimizer-dev
  libgtest-dev libbenchmark-dev libstb-dev libcli11-dev libgeos-dev nlohmann-json3-dev
  libompl-dev
  chromium clang libclang-rt-14-dev python3
  mingw-w64 wine wine64
  libglfw3-dev libgl1-mesa-dri xvfb
  libbullet-dev
  python3-distributed
  time
)
# time: GNU time, for the peak memory in tests/bench/bench_world.sh.
# python3-distributed: Dask, for aggrelod-farm (bake/aggrelod_farm.py) and its tests (tests/farm).
# libbullet-dev: a real physics engine for the test of collision.glb (tests/physics); tests only.
# mingw-w64: the Windows cross build of the runtime (tests/windows); wine, wine64: run its unit
# tests there.
# libglfw3-dev, libgl1-mesa-dri, xvfb: the OpenGL viewer (samples/viewer), tested headless on llvmpipe.
# libompl-dev: motion planning on the hierarchy (planning/, `aggrelod plan`).
# clang (with its libFuzzer runtime): the fuzz targets of tests/fuzz; python3: their
# mutation corpora (tests/fuzz/mutate.py).
# chromium: the web viewer test (tests/web) loads samples/web in headless Chromium.
# node and npm run the glTF validator in the tests. Take them from Debian only when they are
# missing: a node installed otherwise (e.g. a vendor repack) conflicts with Debian's npm.
if ! command -v node >/dev/null 2>&1; then packages+=(nodejs); fi
if ! command -v npm >/dev/null 2>&1; then packages+=(npm); fi

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ "${#missing[@]}" -gt 0 ]; then
  echo "install-deps: installing ${missing[*]}"
  export DEBIAN_FRONTEND=noninteractive
  "${SUDO[@]}" apt-get update
  "${SUDO[@]}" apt-get install -y --no-install-recommends "${missing[@]}"
else
  echo "install-deps: all Debian packages present"
fi

# npm packages, pinned by each folder's package-lock.json: the glTF validator for the tests
# and three.js + 3DTilesRendererJS for the web viewer (samples/web).
npm_ci() {
  local dir="$repo_root/$1" probe="$2"
  local stamp="$dir/node_modules/.package-lock.json"
  if [ ! -d "$dir/node_modules/$probe" ] || [ ! -f "$stamp" ] || [ "$dir/package-lock.json" -nt "$stamp" ]; then
    echo "install-deps: npm ci in $1"
    (cd "$dir" && npm ci --no-audit --no-fund)
  else
    echo "install-deps: $1/node_modules present"
  fi
}
npm_ci tests/validator gltf-validator
npm_ci samples/web 3d-tiles-renderer
