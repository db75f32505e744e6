#!/usr/bin/env bash
# The cmc33 tool against the library built as shared libraries (BUILD_SHARED_LIBS=ON): it calls
# internals of the parts (io's input files and format sniffing) that a shared build must export,
# which the static builds of CI never test. Builds the library and the tool in Release (about 10
# minutes on 2 cores, which is why CI's package_shared builds the library alone), then extracts
# data/Bucky_32x32x32_uint8.nrrd with it.
#   scripts/test-shared-cli.sh [BUILD_DIR]   (default: a temporary folder, removed at the end)
set -euo pipefail
cd "$(dirname "$0")/.."
if [[ $# -ge 1 ]]; then
    dir=$1
else
    dir=$(mktemp -d)
    trap 'rm -rf "$dir"' EXIT
fi
cmake -S . -B "$dir" -G Ninja -DCMAKE_BUILD_TYPE=Release -DBUILD_SHARED_LIBS=ON -DCMC33_BUILD_TESTS=OFF \
      -DCMC33_BUILD_CLI=ON -DCMC33_WERROR=ON >/dev/null
cmake --build "$dir" -j2 --target cmc33_cli
out=$("$dir/cli/cmc33" extract data/Bucky_32x32x32_uint8.nrrd --iso 100.5 --json -o "$dir/bucky.ply")
if ! grep -q '"triangles": 11808' <<<"$out"; then
    echo "test-shared-cli: FAILED: the tool on shared libraries did not extract Bucky's 11808 triangles" >&2
    echo "$out" >&2
    exit 1
fi
echo "test-shared-cli: the cmc33 tool links and runs against the shared libraries (Bucky: 11808 triangles)"
