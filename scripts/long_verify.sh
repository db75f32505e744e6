#!/usr/bin/env bash
# The long topology verification: `cmc33 verify` on a million random cells and 100,000 random
# grids with all three methods, using the Release build. Saves the JSON report and a markdown
# summary (date, seed, machine, per-method results, mismatches per subcase) and prints their names.
#
# Usage: scripts/long_verify.sh [SEED] [--cells N] [--grids N] [--closed N] [--ties N] [--size N]
#                               [--threads N] [--out DIR] [--build DIR | --exe PATH]
#   SEED     default: today's date as YYYYMMDD
#   --out    folder for the reports (default verify-results/); failing fields go to a folder
#            beside them
#   --build  Release build folder (default build/, configured and built if needed)
#   --exe    a cmc33 executable to use instead of building one
# Exit status: 0 if cmc33 matched every field (mc and mc33-lewiner are expected to fail), 1 if it
# did not, 2 on bad usage or if the run could not be made.
# Time: about 35 s on 2 cores (AMD EPYC) for the defaults, 1.11 million fields (docs/verification.md).
set -euo pipefail

usage() {
    sed -n '2,15p' "$0" | sed 's/^# \{0,1\}//' >&2
    exit 2
}

cd "$(dirname "$0")/.."
seed=$(date +%Y%m%d)
cells=1000000
grids=100000
closed=10000
ties=10000
size=5
threads=0
out=verify-results
build=build
exe=
while [ $# -gt 0 ]; do
    case "$1" in
    --cells) cells=${2:?}; shift 2 ;;
    --grids) grids=${2:?}; shift 2 ;;
    --closed) closed=${2:?}; shift 2 ;;
    --ties) ties=${2:?}; shift 2 ;;
    --size) size=${2:?}; shift 2 ;;
    --threads) threads=${2:?}; shift 2 ;;
    --out) out=${2:?}; shift 2 ;;
    --build) build=${2:?}; shift 2 ;;
    --exe) exe=${2:?}; shift 2 ;;
    -h|--help) usage ;;
    -*) echo "long_verify.sh: unknown option $1" >&2; usage ;;
    *) seed=$1; shift ;;
    esac
done
case "$seed" in ''|*[!0-9]*) echo "long_verify.sh: seed '$seed' is not a non-negative integer" >&2; exit 2 ;; esac
command -v python3 >/dev/null || { echo "long_verify.sh: python3 is needed to write the markdown summary" >&2; exit 2; }

# The Release binary.
if [ -n "$exe" ]; then
    cmc33=$exe
else
    if [ ! -f "$build/CMakeCache.txt" ]; then
        cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
    fi
    build_type=$(sed -n 's/^CMAKE_BUILD_TYPE:[A-Z]*=//p' "$build/CMakeCache.txt")
    if [ "$build_type" != Release ]; then
        echo "long_verify.sh: $build is a '$build_type' build; expected Release (use --build DIR)" >&2
        exit 2
    fi
    cmake --build "$build" -j2 --target cmc33_cli >/dev/null
    cmc33="$build/cli/cmc33"
fi
"$cmc33" verify --help >/dev/null 2>&1 || { echo "long_verify.sh: $cmc33 has no verify command" >&2; exit 2; }

day=$(date +%Y-%m-%d)
name="long-verify-$day-seed$seed"
mkdir -p "$out"
json="$out/$name.json"
md="$out/$name.md"
failures="$out/$name-failures"
machine="$(lscpu 2>/dev/null | sed -n 's/^Model name:[[:space:]]*//p' | head -n 1), $(nproc) cores"
commit=$(git rev-parse --short HEAD 2>/dev/null || echo unknown)
if ! git diff --quiet HEAD 2>/dev/null; then commit="$commit (with local changes)"; fi

echo "long_verify.sh: seed $seed, $cells cells, $grids grids, $closed closed grids, $ties tie grids (${size}^3), machine: $machine" >&2
status=0
"$cmc33" verify --method all --seed "$seed" --cells "$cells" --grids "$grids" --closed "$closed" --ties "$ties" --size "$size" \
    --threads "$threads" --failures "$failures" --json --progress >"$json" || status=$?
if [ "$status" -gt 1 ]; then
    echo "long_verify.sh: cmc33 verify failed with status $status" >&2
    exit 2
fi

python3 - "$json" "$md" "$day" "$machine" "$commit" <<'EOF'
import json, sys
path, md_path, day, machine, commit = sys.argv[1:6]
r = json.load(open(path))
f = r["fields"]
rates = r["fields_per_second"]
lines = [
    "# cmc33 long verification, %s" % day,
    "",
    "- seed %d; %d cells, %d grids, %d closed grids and %d tie grids of %d^3 samples; isovalue 0"
    % (r["seed"], f["cell"], f["grid"], f["closed"], f["ties"], r["size"]),
    "- machine: %s; %d threads; commit %s" % (machine, r["threads"], commit),
    "- time: %.1f s (cells %.0f/s, grids %.0f/s, closed %.0f/s, ties %.0f/s, all methods together)"
    % (r["seconds"], rates["cell"], rates["grid"], rates["closed"], rates["ties"]),
    "- reproduce: `cmc33 verify --seed %d --cells %d --grids %d --closed %d --ties %d --size %d`"
    % (r["seed"], f["cell"], f["grid"], f["closed"], f["ties"], r["size"]),
    "",
    "| method | checked | matched | mismatched | undetermined | non-manifold | not embedded | unoriented | errors | mismatched cells / grids / closed / ties |",
    "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
]
for m in r["methods"]:
    k = m["by_kind"]
    lines.append("| %s | %d | %d | %d | %d | %d | %d | %d | %d | %d / %d / %d / %d |" % (
        m["method"], m["checked"], m["matched"], m["mismatched"], m["undetermined"], m["nonmanifold"],
        m["not_embedded"], m["unoriented"], m["errors"], k["cell"]["mismatched"], k["grid"]["mismatched"],
        k["closed"]["mismatched"], k["ties"]["mismatched"]))
order = ["0", "1", "2", "3.1", "3.2", "4.1.1", "4.1.2", "5", "6.1.1", "6.1.2", "6.2", "7.1", "7.2", "7.3",
         "7.4.1", "7.4.2", "8", "9", "10.1.1", "10.1.2", "10.2", "11", "12.1.1", "12.1.2", "12.2", "12.3",
         "13.1", "13.2", "13.3", "13.4", "13.5.1", "13.5.2", "14"]
lines += ["", "## Mismatches per subcase", "",
          "Mismatching / checked fields. A cell counts for the subcase the method gives it; a grid for every",
          "subcase with a face or interior test among its cells, so a grid can count several times.", "",
          "| subcase | " + " | ".join(m["method"] for m in r["methods"]) + " |",
          "|---|" + "---:|" * len(r["methods"])]
for s in order:
    cells = []
    for m in r["methods"]:
        c = m["subcases"].get(s)
        cells.append("-" if c is None else "%d / %d" % (c["mismatched"], c["fields"]))
    if any(c != "-" for c in cells):
        lines.append("| %s | %s |" % (s, " | ".join(cells)))
if r["failures"]:
    lines += ["", "Failing fields (the first of each method): `%s`, listed in `%s`."
              % (r["failures"]["dir"], r["failures"]["list"])]
open(md_path, "w").write("\n".join(lines) + "\n")
EOF

echo "long_verify.sh: wrote $json and $md" >&2
cmc33_mismatched=$(python3 -c 'import json,sys; r=json.load(open(sys.argv[1])); print(sum(m["mismatched"] for m in r["methods"] if m["method"]=="cmc33"))' "$json")
if [ "$cmc33_mismatched" != 0 ]; then
    echo "long_verify.sh: cmc33 mismatched $cmc33_mismatched fields; see $failures/failures.tsv" >&2
    exit 1
fi
