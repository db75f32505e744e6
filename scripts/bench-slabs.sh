#!/usr/bin/env bash
# The out-of-core and MPI figures of README.md and docs/scaling.md, measured here:
#   1. a 2 GiB volume (2048x1024x1024 uint8, written by scripts/make_volume.py) extracted with
#      `--memory-limit 256M` and in memory: wall time, peak RSS, and the two PLY files compared;
#   2. strong scaling of cmc33-mpi on a 1024^3 uint8 volume: P = 1, 2, 4 ranks of one thread
#      (4 is oversubscribed on a 2-core machine), without and with the topology, each PLY compared
#      with cmc33 extract's; per-rank time breakdown and peak RSS from the JSON report.
# The volumes are generated, never stored: in DIR (default /tmp/cmc33-slabs-bench), removed at
# the end. Needs about 5 GiB free there, /usr/bin/time, numpy and Open MPI
# (scripts/install-deps.sh --bench --mpi). Takes about 15 minutes on 2 idle cores; wall times
# depend on the machine's load (printed first), CPU times less.
# Usage: scripts/bench-slabs.sh [DIR]
set -euo pipefail
cd "$(dirname "$0")/.."
dir=${1:-/tmp/cmc33-slabs-bench}
py=/usr/bin/python3
for tool in /usr/bin/time "$py" mpirun; do
    command -v "$tool" >/dev/null || { echo "bench-slabs: $tool is missing (scripts/install-deps.sh --bench --mpi)" >&2; exit 1; }
done
"$py" -c "import numpy" 2>/dev/null || { echo "bench-slabs: numpy is missing for $py (scripts/install-deps.sh --bench)" >&2; exit 1; }
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release -DCMC33_WERROR=ON >/dev/null
cmake --build build -j2 --target cmc33_cli cmc33_mpi
cmc33=$PWD/build/cli/cmc33
cmc33_mpi=$PWD/build/mpi/cmc33-mpi
mkdir -p "$dir"
trap 'rm -f "$dir"/*.nrrd "$dir"/*.ply "$dir"/*.json "$dir"/*.time; rmdir "$dir" 2>/dev/null || true' EXIT
free_kb=$(df -Pk "$dir" | awk 'NR == 2 {print $4}')
if (( free_kb < 5 * 1024 * 1024 )); then
    echo "bench-slabs: $dir has $((free_kb / 1024)) MiB free; the run needs about 5 GiB" >&2
    exit 1
fi
mpirun_flags=(--oversubscribe)
[[ $(id -u) -eq 0 ]] && mpirun_flags+=(--allow-run-as-root)

# wall seconds and peak RSS (MiB) from a /usr/bin/time -v log
timed() { # timed LOG COMMAND...
    local log=$1
    shift
    /usr/bin/time -v -o "$log" "$@"
}
wall() { awk -F': ' '/Elapsed \(wall clock\)/ {n = split($2, t, ":"); s = 0; for (i = 1; i <= n; ++i) s = s * 60 + t[i]; print s}' "$1"; }
rss_mib() { awk -F': ' '/Maximum resident set size/ {printf "%.0f", $2 / 1024}' "$1"; }
cpu() { awk -F': ' '/User time|System time/ {s += $2} END {printf "%.1f", s}' "$1"; } # user + system seconds
json() { "$py" -c "import json, sys; d = json.load(open(sys.argv[1])); print(eval(sys.argv[2]))" "$@"; }

echo "date: $(date -u '+%Y-%m-%d %H:%M UTC'); $(nproc) cores; $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2- | sed 's/^ //'); $(mpirun --version | head -1); load average $(cut -d' ' -f1-3 /proc/loadavg)"

echo "== 1. a 2 GiB volume within --memory-limit 256M"
"$py" scripts/make_volume.py "$dir/big.nrrd" 2048 1024 1024 --periods 2
timed "$dir/slabs.time" "$cmc33" extract "$dir/big.nrrd" -i 128 -o "$dir/slabs.ply" --memory-limit 256M --json --quiet >"$dir/slabs.json"
timed "$dir/memory.time" "$cmc33" extract "$dir/big.nrrd" -i 128 -o "$dir/memory.ply" --no-topology --json --quiet >"$dir/memory.json"
timed "$dir/lean.time" "$cmc33" extract "$dir/big.nrrd" -i 128 -o "$dir/lean.ply" --memory-limit 256M --no-topology --json --quiet >"$dir/lean.json"
lean_same=$(cmp -s "$dir/lean.ply" "$dir/memory.ply" && echo "identical" || echo "DIFFERENT")
same=$(cmp -s "$dir/slabs.ply" "$dir/memory.ply" && echo "identical" || echo "DIFFERENT")
echo "volume 2048x1024x1024 uint8 ($(stat -c %s "$dir/big.nrrd") bytes), iso 128: $(json "$dir/slabs.json" 'd["vertices"]') vertices, $(json "$dir/slabs.json" 'd["triangles"]') triangles, PLY $(stat -c %s "$dir/slabs.ply") bytes"
echo "  --memory-limit 256M (topology and geometry too): $(wall "$dir/slabs.time") s wall, $(cpu "$dir/slabs.time") s CPU, peak RSS $(rss_mib "$dir/slabs.time") MiB, $(json "$dir/slabs.json" 'd["slabs"]') slabs; $(json "$dir/slabs.json" 'd["phases_seconds"]')"
echo "  in memory (--no-topology):                      $(wall "$dir/memory.time") s wall, $(cpu "$dir/memory.time") s CPU, peak RSS $(rss_mib "$dir/memory.time") MiB"
echo "  --memory-limit 256M --no-topology:              $(wall "$dir/lean.time") s wall, $(cpu "$dir/lean.time") s CPU, peak RSS $(rss_mib "$dir/lean.time") MiB; $(json "$dir/lean.json" 'd["phases_seconds"]')"
echo "  the PLY files against the in-memory one: $same (with topology), $lean_same (without)"
echo "  topology: $(json "$dir/slabs.json" 'd["topology"]["euler"], d["topology"]["betti"], "embedded" if d["geometry"]["embedded"] else "NOT embedded"')"
rm -f "$dir/big.nrrd" "$dir/slabs.ply" "$dir/memory.ply" "$dir/lean.ply"

echo "== 2. strong scaling on 1024^3 (ranks of one thread; 4 ranks oversubscribe the $(nproc) cores)"
"$py" scripts/make_volume.py "$dir/cube.nrrd" 1024 1024 1024 --periods 2
timed "$dir/ref.time" "$cmc33" extract "$dir/cube.nrrd" -i 128 -o "$dir/ref.ply" --json --quiet >"$dir/ref.json"
echo "cmc33 extract in memory, $(nproc) threads, with topology: $(wall "$dir/ref.time") s wall, $(cpu "$dir/ref.time") s CPU (extraction $(json "$dir/ref.json" 'round(d["seconds"], 2)') s), peak RSS $(rss_mib "$dir/ref.time") MiB; $(json "$dir/ref.json" 'd["triangles"]') triangles"
for topology in --no-topology ""; do
    for p in 1 2 4; do
        out="$dir/mpi.json"
        timed "$dir/mpi.time" mpirun "${mpirun_flags[@]}" -n "$p" "$cmc33_mpi" extract "$dir/cube.nrrd" -i 128 -o "$dir/mpi.ply" \
            --threads 1 --json --quiet $topology >"$out"
        same=$(cmp -s "$dir/mpi.ply" "$dir/ref.ply" && echo "identical" || echo "DIFFERENT")
        agree=$(json "$out" 'd["topology"] is None or d["topology"] == json.load(open(sys.argv[1].replace("mpi.json", "ref.json")))["topology"]')
        echo "P=$p ${topology:-with topology}: $(wall "$dir/mpi.time") s wall (mpirun included), $(cpu "$dir/mpi.time") s CPU, PLY $same, topology equal: $agree"
        json "$out" '"  per rank: " + "; ".join("%s %s" % (k, [round(x, 2) for x in v]) for k, v in d["rank_seconds"].items())'
        json "$out" '"  peak RSS per rank (MiB): %s; read per rank (MiB): %s" % ([round(x / 2**20) for x in d["peak_rss_bytes"]], [round(x / 2**20) for x in d["read_bytes"]])'
    done
done
