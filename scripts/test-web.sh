#!/usr/bin/env bash
# The executable paper's tests (CI runs this): builds the page (scripts/build-web.sh, which installs
# what is missing) and the native CLI the page is compared with, then runs web/test/ with Node's
# test runner: the WebAssembly module against the CLI, and the page in Debian's headless chromium
# (puppeteer-core). Screenshots of every view: build/web-screenshots/.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/build-web.sh
if [[ ! -f build/build.ninja ]]; then
    cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
fi
cmake --build build -j2 --target cmc33_cli
cd web
node --no-experimental-fetch --test test/wasm.test.mjs test/browser.test.mjs
