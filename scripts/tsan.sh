#!/usr/bin/env bash
# ThreadSanitizer run of the multithreaded code: the extractor (thread-count identity, strided
# views), the verifier (in-process, same report for 1 and 3 threads, external commands run by
# threads) and mesh_geometry's threaded pair search. Debug at -O1 (asserts on, TSan's overhead
# kept moderate); a few minutes on 2 cores. Any report fails the run (halt_on_error, and TSan's
# exit code 66 fails the test).
# Usage: scripts/tsan.sh [JOBS]   (after scripts/install-deps.sh)
set -euo pipefail
cd "$(dirname "$0")/.."
jobs="${1:-2}"
cmake -S . -B build-tsan -G Ninja -DCMAKE_BUILD_TYPE=Debug -DCMAKE_CXX_FLAGS_DEBUG="-O1 -g" \
      -DCMC33_TSAN=ON -DCMC33_WERROR=ON >/dev/null
cmake --build build-tsan -j"$jobs" --target cmc33_cli test_core test_verify test_dataset test_mesh_geometry test_extracted_check \
      test_labels
export TSAN_OPTIONS="halt_on_error=1 second_deadlock_stack=1 suppressions=$PWD/tests/tsan.supp"
# Extract.* holds the thread-count identity test, Passes.* the progress, cancel and executor tests; the exhaustive table and subcase suites are
# single-threaded and left out, as are the stress runs of `cmc33 verify` (label slow). Labels: the
# label maps' cell pass and smoothing filter at 1 to 20 threads.
ctest --test-dir build-tsan -j"$jobs" --output-on-failure --timeout 600 -LE slow \
      -R '^(Extract|Passes|RandomFields|Verify|VerifyCatches|Dataset|MeshGeometry|ExtractedCheck|Sweep)\.|^Labels\.SameOutputForEveryThreadCount$'
