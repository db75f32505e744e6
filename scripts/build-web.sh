#!/usr/bin/env bash
# Builds the executable paper into build/web/: the library compiled to WebAssembly by Debian's
# emscripten (CMake, build/wasm; web/CMakeLists.txt), the page bundled by esbuild from web/ with
# the npm packages of web/package-lock.json, the bundled volumes (data/, and ../shared/data/volumes
# when that folder is beside the clone) and the sweep data files of docs/figures/*.json that the
# page opens (web/tools/index.mjs picks them).
# Installs what is missing first (scripts/install-deps.sh --web, npm ci). Serve the folder with
# any static file server, e.g.  python3 -m http.server -d build/web 8033  and open
# http://localhost:8033/
set -euo pipefail
cd "$(dirname "$0")/.."
root=$PWD
out=build/web

scripts/install-deps.sh --web
# Debian's emscripten runs its optimizer under node and requires acorn from Debian's node path
export NODE_PATH="/usr/share/nodejs${NODE_PATH:+:$NODE_PATH}"

echo "build-web: the WebAssembly module (build/wasm)" >&2
emcmake cmake -S . -B build/wasm -G Ninja -DCMAKE_BUILD_TYPE=Release -DCMC33_BUILD_TESTS=OFF \
    -DCMC33_BUILD_CLI=OFF >/dev/null
cmake --build build/wasm -j2 --target cmc33_wasm

echo "build-web: the page ($out)" >&2
cd web
if [[ ! -d node_modules || package-lock.json -nt node_modules/.package-lock.json ]]; then
    npm ci --no-audit --no-fund --loglevel=error
fi
rm -rf "$root/$out"
node build.mjs "$root/$out"
cd "$root"
cp build/wasm/web/cmc33.mjs build/wasm/web/cmc33.wasm "$out/"

mkdir -p "$out/volumes" "$out/figures"
cp data/*.nrrd "$out/volumes/"
if [[ -d ../shared/data/volumes ]]; then
    cp ../shared/data/volumes/*.nrrd "$out/volumes/"
fi
# the sweep data files of docs/figures/ that the page opens (index.mjs copies those and lists them)
node --no-experimental-fetch web/tools/index.mjs "$out" docs/figures
echo "build-web: done; serve it with: python3 -m http.server -d $out 8033" >&2
