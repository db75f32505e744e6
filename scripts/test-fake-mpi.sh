#!/usr/bin/env bash
# A half-installed MPI (an mpicxx whose include folder is missing, as Debian's openmpi-bin without
# libopenmpi-dev) must not stop a build that does not need MPI: the default configure succeeds and
# says in one line why cmc33-mpi is skipped, while asking for cmc33-mpi still fails. Configures only.
set -euo pipefail
cd "$(dirname "$0")/.."
fake=$PWD/tests/cmake/fake-mpi
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
export PATH="$fake:$PATH"
[[ $(command -v mpicxx) == "$fake/mpicxx" ]] || { echo "test-fake-mpi: the fake mpicxx is not first on PATH" >&2; exit 1; }

if ! cmake -S . -B "$dir/default" -G Ninja -DCMC33_BUILD_TESTS=OFF >"$dir/default.log" 2>&1; then
    cat "$dir/default.log" >&2
    echo "test-fake-mpi: FAILED: the default configure stopped on the half-installed MPI" >&2
    exit 1
fi
if ! grep -q "cmc33-mpi: skipped (MPI is incomplete: mpicxx cannot compile #include <mpi.h>" "$dir/default.log"; then
    cat "$dir/default.log" >&2
    echo "test-fake-mpi: FAILED: the configure does not say why cmc33-mpi is skipped" >&2
    exit 1
fi
grep "cmc33-mpi: skipped" "$dir/default.log"
# the Python package's and the page's configure (no CLI) never look for MPI
if ! cmake -S . -B "$dir/nocli" -G Ninja -DCMC33_BUILD_TESTS=OFF -DCMC33_BUILD_CLI=OFF >"$dir/nocli.log" 2>&1; then
    cat "$dir/nocli.log" >&2
    echo "test-fake-mpi: FAILED: a configure without the CLI stopped on the half-installed MPI" >&2
    exit 1
fi
if cmake -S . -B "$dir/asked" -G Ninja -DCMC33_BUILD_TESTS=OFF -DCMC33_BUILD_MPI=ON >"$dir/asked.log" 2>&1; then
    echo "test-fake-mpi: FAILED: -DCMC33_BUILD_MPI=ON configured without a usable MPI" >&2
    exit 1
fi
echo "test-fake-mpi: 3 passed, 0 failed (the default and the CLI-less configures skip cmc33-mpi; CMC33_BUILD_MPI=ON fails)"
