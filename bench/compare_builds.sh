#!/usr/bin/env bash
# Times two cmc33 executables on the same volumes and isovalues, interleaved so that both see the
# same machine load: for each case, ROUNDS rounds of `extract --repeat 15 --threads 1 --no-topology`
# per executable, alternating; prints the best of the rounds' medians for each and their ratio.
#
# Usage: bench/compare_builds.sh OLD_CMC33 NEW_CMC33 [ROUNDS] [FILE:ISO ...]
#   default cases: aneurism, bonsai and CThead of ../shared/data/volumes at half-integer and
#   integer isovalues.
set -euo pipefail
[ $# -ge 2 ] || { sed -n '2,9p' "$0" | sed 's/^# \{0,1\}//' >&2; exit 2; }
old=$1 new=$2 rounds=${3:-5}
shift $(( $# >= 3 ? 3 : 2 ))
vol="$(dirname "$0")/../../shared/data/volumes"
cases=("$@")
if [ ${#cases[@]} -eq 0 ]; then
    cases=("$vol/aneurism_256x256x256_uint8.nrrd:80.5" "$vol/bonsai_256x256x256_uint8.nrrd:40.5"
           "$vol/CThead_256x256x113_uint16.nrrd:650.5" "$vol/aneurism_256x256x256_uint8.nrrd:80"
           "$vol/bonsai_256x256x256_uint8.nrrd:40" "$vol/CThead_256x256x113_uint16.nrrd:650")
fi
seconds() { "$1" extract "$2" --iso "$3" --threads 1 --repeat 15 --no-topology --json |
            python3 -c 'import json,sys; print(json.load(sys.stdin)["seconds"])'; }
printf '| volume | iso | old s | new s | new / old |\n|---|---:|---:|---:|---:|\n'
for c in "${cases[@]}"; do
    file=${c%:*} iso=${c##*:}
    best_old=9e9 best_new=9e9
    for _ in $(seq "$rounds"); do
        o=$(seconds "$old" "$file" "$iso"); n=$(seconds "$new" "$file" "$iso")
        best_old=$(python3 -c "print(min($best_old, $o))"); best_new=$(python3 -c "print(min($best_new, $n))")
    done
    python3 -c "print('| %s | %s | %.4f | %.4f | %.3f |' % ('$(basename "$file" .nrrd)', '$iso', $best_old, $best_new, $best_new / $best_old))"
done
