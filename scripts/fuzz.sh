#!/usr/bin/env bash
# Builds the libFuzzer targets with clang into build-fuzz/ and runs each for SECONDS (default 30)
# on a copy of its seed corpus (fuzz/corpus/<target>/ is only read). Prints per target the
# executions, coverage (cov, ft: libFuzzer's final figures) and crashes; exits 1 if any target
# crashed, leaked, hung or ran out of memory. Crash inputs are kept in build-fuzz/fuzz-work/.
#
# Usage: scripts/fuzz.sh [SECONDS] [TARGET...]   targets: nrrd nhdr mha mhd vtk raw ply obj stl off dicom tiff
#   nifti npy vti labelnames (colour tables and .seg.nrrd segment names). The build reads DICOM
#   through GDCM where it is installed (fuzz_dicom fuzzes the code around it; without GDCM every
#   DICOM input is refused and the target fuzzes little).
# Environment: FUZZ_RUNS=N stops each target after N executions instead (SECONDS then caps the
# time); FUZZ_NO_BUILD=1 skips the build (for running several instances side by side).
set -euo pipefail
cd "$(dirname "$0")/.."

seconds=30
if [[ $# -gt 0 && "$1" =~ ^[0-9]+$ ]]; then
    seconds=$1
    shift
fi
all=(nrrd nhdr mha mhd vtk raw ply obj stl off dicom tiff nifti npy vti labelnames)
targets=("$@")
[[ ${#targets[@]} -eq 0 ]] && targets=("${all[@]}")
for t in "${targets[@]}"; do
    [[ " ${all[*]} " == *" $t "* ]] || { echo "fuzz.sh: unknown target \"$t\"; expected one of ${all[*]}" >&2; exit 2; }
done

if [[ "${FUZZ_NO_BUILD:-0}" != 1 ]]; then
    scripts/install-deps.sh --fuzz
    if [[ ! -f build-fuzz/CMakeCache.txt ]]; then
        CC=clang CXX=clang++ cmake -S . -B build-fuzz -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
            -DCMC33_BUILD_FUZZ=ON -DCMC33_BUILD_TESTS=OFF -DCMC33_BUILD_CLI=OFF -DCMC33_WITH_GDCM=ON >/dev/null
    fi
    # the targets alone: they link the readers (cmc33::io), not the rest of the library
    cmake --build build-fuzz -j2 --target "${all[@]/#/fuzz_}" >/dev/null
fi

runs=()
[[ -n "${FUZZ_RUNS:-}" ]] && runs=(-runs="$FUZZ_RUNS")
failed=0
# One target per core at a time (two at once on CI's two cores); the table is printed in order.
jobs=${FUZZ_JOBS:-2}
fuzz_one() {
    local t=$1 work=build-fuzz/fuzz-work/$1
    rm -rf "$work/corpus"
    mkdir -p "$work/corpus" "$work/artifacts"
    rm -f "$work/result" "$work/crashes"
    cp fuzz/corpus/"$t"/* "$work/corpus/"
    local before start status=0 elapsed execs last cov ft crashes
    before=$(find "$work/artifacts" -type f | wc -l)
    start=$(date +%s)
    build-fuzz/fuzz/fuzz_"$t" -max_total_time="$seconds" "${runs[@]}" -rss_limit_mb=2048 \
        -malloc_limit_mb=256 -timeout=10 -print_final_stats=1 \
        -artifact_prefix="$work/artifacts/" "$work/corpus" >"$work/log" 2>&1 || status=$?
    elapsed=$(( $(date +%s) - start ))
    execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$work/log" | tail -1)
    last=$(grep -E '^#[0-9]+' "$work/log" | grep -E 'cov: ' | tail -1 || true)
    cov=$(sed -n 's/.* cov: \([0-9]*\).*/\1/p' <<<"$last")
    ft=$(sed -n 's/.* ft: \([0-9]*\).*/\1/p' <<<"$last")
    crashes=$(( $(find "$work/artifacts" -type f | wc -l) - before ))
    [[ $status -ne 0 && $crashes -eq 0 ]] && crashes=1 # died without an artifact
    printf '%-6s %12s %8s %6s %6s %8s\n' "$t" "${execs:-?}" "$elapsed" "${cov:-?}" "${ft:-?}" "$crashes" >"$work/result"
    echo "$crashes" >"$work/crashes"
}
for t in "${targets[@]}"; do
    while [[ $(jobs -rp | wc -l) -ge $jobs ]]; do wait -n || true; done
    fuzz_one "$t" &
done
wait
printf '%-6s %12s %8s %6s %6s %8s\n' target execs seconds cov ft crashes
for t in "${targets[@]}"; do
    work=build-fuzz/fuzz-work/$t
    cat "$work/result" 2>/dev/null || echo "$t: no result"
    if [[ "$(cat "$work/crashes" 2>/dev/null || echo 1)" != 0 ]]; then
        failed=1
        echo "  see $work/log; inputs in $work/artifacts/" >&2
    fi
done
exit $failed
