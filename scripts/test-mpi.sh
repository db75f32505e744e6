#!/usr/bin/env bash
# The MPI tests (label mpi, tests/mpi/check_mpi.py): cmc33-mpi with 1 to 4 ranks against cmc33
# extract, on the build of scripts/test.sh. Fails when cmc33-mpi was not built (MPI missing:
# scripts/install-deps.sh --mpi). Usage: scripts/test-mpi.sh   (about 2 minutes on 2 cores)
set -euo pipefail
cd "$(dirname "$0")/.."
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release -DCMC33_WERROR=ON >/dev/null
cmake --build build -j2
if [[ ! -x build/mpi/cmc33-mpi ]]; then
    echo "test-mpi: build/mpi/cmc33-mpi was not built: MPI was not found (scripts/install-deps.sh --mpi)" >&2
    exit 1
fi
ctest --test-dir build -L mpi --output-on-failure --timeout 900
