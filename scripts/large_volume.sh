#!/usr/bin/env bash
# Extracts a 1300^3 uint8 volume (2,197,000,000 samples, more than 2^31) and prints the time, the
# peak resident memory and what came out: tests/core/test_large_volume.cpp (label slow) built in
# Release, run alone under /usr/bin/time -v. Needs about 6 GiB of available memory.
# Usage: scripts/large_volume.sh   (after scripts/install-deps.sh)
set -euo pipefail
cd "$(dirname "$0")/.."
if [[ ! -x /usr/bin/time ]]; then
    echo "large_volume.sh: /usr/bin/time is missing (Debian package: time)" >&2
    exit 1
fi
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release -DCMC33_WERROR=ON >/dev/null
cmake --build build -j2 --target test_large_volume
log=$(mktemp)
trap 'rm -f "$log"' EXIT
status=0
/usr/bin/time -v -o "$log" build/tests/core/test_large_volume --gtest_brief=1 || status=$?
echo "date: $(date -u '+%Y-%m-%d %H:%M UTC'); $(nproc) cores; $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2- | sed 's/^ //')"
grep -E 'Elapsed \(wall clock\)|Maximum resident set size' "$log" | sed 's/^\s*//'
exit "$status"
