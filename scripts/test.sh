#!/usr/bin/env bash
# Builds cmc33 (Release, warnings as errors) and runs every test, including the topology
# stress run of the verifier, but the MPI ones (scripts/test-mpi.sh runs those).
# Usage: scripts/test.sh   (after scripts/install-deps.sh)
set -euo pipefail
cd "$(dirname "$0")/.."
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release -DCMC33_WERROR=ON >/dev/null
cmake --build build -j2
ctest --test-dir build -j2 --output-on-failure --timeout 1800 -LE mpi
