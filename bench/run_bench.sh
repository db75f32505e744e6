#!/usr/bin/env bash
# The one-invocation comparison of cmc33 with its peers (VTK flying edges and marching cubes,
# scikit-image's Lewiner marching cubes) on real and synthetic volumes. bench/README.md explains
# the columns and how memory is measured.
#
# Usage: bench/run_bench.sh [--repeat R] [--cases a,b,...] [--quick] [--out DIR] [--volumes DIR]
#                           [--build DIR] [--work DIR]
set -euo pipefail

usage() {
    cat <<'EOF'
usage: bench/run_bench.sh [options]
Builds cmc33 and its benchmark drivers (Release, -DCMC33_BUILD_BENCH=ON), makes the synthetic
volumes, times every tool on every case (each run in its own process, under GNU time for the peak
memory), and writes RESULTS.jsonl and a Markdown table RESULTS.md (also printed).

  --repeat R      extractions per tool and case; the median is reported (default 5; --quick: 1)
  --cases LIST    comma-separated subset of: aneurism,bonsai,engine,CThead,sines,noise
                  (sines512 and noise128 are accepted for sines and noise); default all
  --quick         smoke test: sines 128^3 and noise 64^3 instead of 512^3 and 128^3, 1 repeat
  --out DIR       where results.jsonl, results.md and build.log go (default WORK/results)
  --volumes DIR   the shared volumes (default ../shared/data/volumes from the repository root)
  --build DIR     the build folder (default build-bench in the repository root)
  --work DIR      where the synthetic volumes are made and kept (default bench-work in the
                  repository root); existing ones are reused
EOF
}

prog="run_bench.sh"
die() { echo "$prog: $*" >&2; exit 1; }
usage_error() { echo "$prog: $* (try --help)" >&2; exit 2; }

repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build="$repo/build-bench"
work="$repo/bench-work"
volumes="$repo/../shared/data/volumes"
out=""
repeat=""
quick=0
cases_arg=""

while [[ $# -gt 0 ]]; do
    case "$1" in
        -h|--help) usage; exit 0 ;;
        --quick) quick=1; shift; continue ;;
        --repeat|--cases|--out|--volumes|--build|--work)
            [[ $# -ge 2 ]] || usage_error "$1 needs a value"
            case "$1" in
                --repeat) repeat="$2" ;;
                --cases) cases_arg="$2" ;;
                --out) out="$2" ;;
                --volumes) volumes="$2" ;;
                --build) build="$2" ;;
                --work) work="$2" ;;
            esac
            shift 2 ;;
        *) usage_error "unknown argument \"$1\"" ;;
    esac
done
if [[ -n "$repeat" ]]; then
    [[ "$repeat" =~ ^[0-9]+$ && "$repeat" -ge 1 && "$repeat" -le 1000 ]] ||
        usage_error "--repeat \"$repeat\" is not an integer in [1, 1000]"
else
    repeat=$((quick ? 1 : 5))
fi
[[ -n "$out" ]] || out="$work/results"

# The cases: name, volume file (a name alone is looked up in --volumes), isovalue. The isovalues
# of the real volumes are those the volumes' README suggests (the middle of its range for engine
# and for CThead's bone).
sines_n=$((quick ? 128 : 512))
noise_n=$((quick ? 64 : 128))
all_cases=(aneurism bonsai engine CThead sines noise)
declare -A case_file=(
    [aneurism]=aneurism_256x256x256_uint8.nrrd
    [bonsai]=bonsai_256x256x256_uint8.nrrd
    [engine]=engine_256x256x128_uint8.nrrd
    [CThead]=CThead_256x256x113_uint16.nrrd
    [sines]="$work/sines$sines_n.nrrd"
    [noise]="$work/noise$noise_n.nrrd"
)
declare -A case_iso=([aneurism]=80 [bonsai]=40 [engine]=80 [CThead]=1500 [sines]=0 [noise]=0)
declare -A case_label=([aneurism]=aneurism [bonsai]=bonsai [engine]=engine [CThead]=CThead
                       [sines]="sines$sines_n" [noise]="noise$noise_n")

cases=()
if [[ -z "$cases_arg" ]]; then
    cases=("${all_cases[@]}")
else
    IFS=',' read -r -a wanted <<< "$cases_arg"
    for c in "${wanted[@]}"; do
        case "$c" in sines512) c=sines ;; noise128) c=noise ;; esac
        [[ -n "${case_iso[$c]+x}" ]] || usage_error "unknown case \"$c\"; expected some of ${all_cases[*]}"
        cases+=("$c")
    done
    [[ ${#cases[@]} -gt 0 ]] || usage_error "--cases is empty"
fi

# ---- tools this machine must have -------------------------------------------------------------
python=/usr/bin/python3
[[ -x "$python" ]] || die "$python is missing (Debian: apt-get install python3); it runs the skimage driver and writes the results"
time_version=$(/usr/bin/time --version 2>&1) || true
[[ "$time_version" == *GNU* ]] ||
    die "GNU time (/usr/bin/time) is missing; it measures the peak memory: apt-get install time (or scripts/install-deps.sh --bench)"
command -v cmake >/dev/null || die "cmake is missing (scripts/install-deps.sh installs it)"
command -v ninja >/dev/null || die "ninja is missing (Debian: apt-get install ninja-build)"
for c in "${cases[@]}"; do
    f="${case_file[$c]}"
    if [[ "$f" != /* ]]; then
        [[ -d "$volumes" ]] || die "the volumes folder $volumes does not exist; pass --volumes DIR or leave out the real cases with --cases sines,noise"
        [[ -r "$volumes/$f" ]] || die "case $c: $volumes/$f is missing or unreadable"
        case_file[$c]="$(cd "$volumes" && pwd)/$f"
    fi
done

mkdir -p "$out" "$work" || die "cannot create $out or $work"
out=$(cd "$out" && pwd)
work=$(cd "$work" && pwd)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

# ---- build ------------------------------------------------------------------------------------
echo "$prog: building in $build (log: $out/build.log)" >&2
build_failed() { tail -n 20 "$out/build.log" >&2; die "the build failed; see $out/build.log"; }
cmake -S "$repo" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release -DCMC33_BUILD_BENCH=ON \
    > "$out/build.log" 2>&1 || build_failed
# cmc33_vtk_bench is a target only when CMake found VTK.
ninja -C "$build" -t targets all > "$tmp/targets" 2>> "$out/build.log" || build_failed
targets=(cmc33_cli cmc33_make_field)
have_vtk=0
if grep -q '^cmc33_vtk_bench:' "$tmp/targets"; then
    targets+=(cmc33_vtk_bench)
    have_vtk=1
fi
ninja -C "$build" "${targets[@]}" >> "$out/build.log" 2>&1 || build_failed

cmc33="$build/cli/cmc33"
make_field="$build/bench/cmc33_make_field"
vtk_bench="$build/bench/cmc33_vtk_bench"
[[ -x "$cmc33" && -x "$make_field" ]] || die "the build did not produce $cmc33 and $make_field"

notes=()
if ((!have_vtk)); then
    notes+=("VTK columns skipped: CMake did not find VTK (CommonCore CommonDataModel FiltersCore), so cmc33_vtk_bench was not built (Debian: apt-get install libvtk9-dev)")
fi
have_skimage=0
if skimage_error=$("$python" -c "import numpy, skimage.measure" 2>&1); then
    have_skimage=1
else
    notes+=("skimage column skipped: $python cannot import it ($(tail -n 1 <<< "$skimage_error"); Debian: apt-get install python3-skimage python3-numpy)")
fi
for n in "${notes[@]}"; do echo "$prog: $n" >&2; done

# ---- synthetic volumes ------------------------------------------------------------------------
make_volume() { # kind n file: made when missing or older than the generator
    local kind=$1 n=$2 file=$3
    if [[ -f "$file" && "$file" -nt "$make_field" ]]; then
        echo "$prog: reusing $file" >&2
        return
    fi
    echo "$prog: making $file ($kind, $n^3 float32)" >&2
    "$make_field" "$kind" "$file" "$n" || die "cmc33_make_field could not write $file"
}
for c in "${cases[@]}"; do
    case "$c" in
        sines) make_volume sines "$sines_n" "${case_file[sines]}" ;;
        noise) make_volume noise "$noise_n" "${case_file[noise]}" ;;
    esac
done

# ---- the runs ---------------------------------------------------------------------------------
nproc=$(nproc)
# tool id | threads (0: all cores)
runs=("cmc33|1" "cmc33|0" "cmc33-mc|1")
if ((have_vtk)); then runs+=("vtk-flying-edges|1" "vtk-flying-edges|0" "vtk-marching-cubes|1"); fi
if ((have_skimage)); then runs+=("skimage-lewiner|1"); fi
if ((nproc == 1)); then
    notes+=("one CPU: the all-threads rows are left out")
    runs=("cmc33|1" "cmc33-mc|1")
    if ((have_vtk)); then runs+=("vtk-flying-edges|1" "vtk-marching-cubes|1"); fi
    if ((have_skimage)); then runs+=("skimage-lewiner|1"); fi
fi

# record.py: turns one run (the tool's JSON output, GNU time's peak RSS) into a line of
# results.jsonl, and prints a short summary of it.
read -r -d '' record_py <<'PY' || true
import json, sys
case, label, path, iso, tool, status, rss_path, out_path, err_path, info_path, jsonl = sys.argv[1:]
status = int(status)
info = json.load(open(info_path))
dims, vtype = info["dims"], info["type"]
size = {"int8": 1, "uint8": 1, "int16": 2, "uint16": 2, "int32": 4, "uint32": 4, "float": 4, "double": 8}[vtype]
cells = (dims[0] - 1) * (dims[1] - 1) * (dims[2] - 1)
rec = {"case": case, "label": label, "file": path, "iso": float(iso), "dims": dims, "type": vtype,
       "tool": tool, "cells": cells, "input_bytes": dims[0] * dims[1] * dims[2] * size}
rss = None
for line in open(rss_path).read().split("\n")[::-1]:  # GNU time -o: its notes first, %M last
    if line.strip().isdigit():
        rss = int(line)
        break
rec["peak_rss_kib"] = rss
stdout = open(out_path).read()
stderr_lines = [l for l in open(err_path).read().split("\n") if l.strip()]
if status != 0:
    why = stderr_lines[-1] if stderr_lines else f"exited with status {status}"
    if status > 128 and not stderr_lines:
        why = f"killed by signal {status - 128}"
    rec["error"] = why
else:
    try:
        r = json.loads(stdout)
    except ValueError:
        r = None
        rec["error"] = "printed no JSON result: " + (stdout.strip().split("\n") or [""])[0][:200]
    if r is not None:
        vertices = r.get("vertices", r.get("points"))
        rec.update({"seconds": r["seconds"], "runs_seconds": r["runs_seconds"], "vertices": vertices,
                    "triangles": r["triangles"], "threads": r["threads"]})
        for k in ("method", "smp_backend", "vtk_version", "version", "numpy_version"):
            if k in r:
                rec[k] = r[k]
        rec["mcells_per_s"] = cells / r["seconds"] / 1e6 if r["seconds"] > 0 else None
        rec["mesh_bytes"] = 12 * (vertices + r["triangles"])
with open(jsonl, "a") as f:
    f.write(json.dumps(rec) + "\n")
if "error" in rec:
    print("FAILED: " + rec["error"])
else:
    mib = f"{rss / 1024:.1f} MiB peak" if rss is not None else "peak RSS unknown"
    print(f"{rec['seconds']:.4g} s, {rec['triangles']} triangles, {mib}")
PY

results="$out/results.jsonl"
: > "$results"
total=$(( ${#cases[@]} * ${#runs[@]} ))
i=0
failed=0
for c in "${cases[@]}"; do
    file="${case_file[$c]}"
    iso="${case_iso[$c]}"
    "$cmc33" info "$file" --json > "$tmp/info.json" 2> "$tmp/info.err" ||
        die "case $c: cmc33 info cannot read $file: $(tail -n 1 "$tmp/info.err")"
    for run in "${runs[@]}"; do
        tool=${run%%|*}
        threads=${run##*|}
        i=$((i + 1))
        case "$tool" in
            cmc33) cmd=("$cmc33" extract "$file" --iso "$iso" --json --no-topology --repeat "$repeat" --threads "$threads") ;;
            cmc33-mc) cmd=("$cmc33" extract "$file" --iso "$iso" --json --no-topology --repeat "$repeat" --threads "$threads" --method mc) ;;
            vtk-flying-edges) cmd=("$vtk_bench" "$file" "$iso" --repeat "$repeat" --algorithm flying-edges --threads "$threads") ;;
            vtk-marching-cubes) cmd=("$vtk_bench" "$file" "$iso" --repeat "$repeat" --algorithm marching-cubes --threads "$threads") ;;
            skimage-lewiner) cmd=("$python" "$repo/bench/skimage_bench.py" "$file" "$iso" --repeat "$repeat") ;;
        esac
        label="${case_label[$c]}"
        threads_text=$([[ $threads == 0 ]] && echo "all threads" || echo "$threads thread")
        printf '%s: [%d/%d] %-9s %-19s %-11s ' "$prog" "$i" "$total" "$label" "$tool" "$threads_text" >&2
        status=0
        /usr/bin/time -f %M -o "$tmp/rss" -- "${cmd[@]}" > "$tmp/out" 2> "$tmp/err" || status=$?
        summary=$("$python" -c "$record_py" "$c" "$label" "$file" "$iso" "$tool" "$status" "$tmp/rss" \
                  "$tmp/out" "$tmp/err" "$tmp/info.json" "$results") || die "could not record the result in $results"
        echo "$summary" >&2
        [[ $status -eq 0 ]] || failed=$((failed + 1))
    done
done

# ---- the table --------------------------------------------------------------------------------
model=$(lscpu 2>/dev/null | sed -n 's/^Model name: *//p') || true
model=${model%%$'\n'*}
[[ -n "$model" ]] || model="unknown (lscpu gave no model name)"
commit=$(git -C "$repo" rev-parse --short HEAD 2>/dev/null || echo "unknown (not a git checkout)")
if [[ -n "$(git -C "$repo" status --porcelain --untracked-files=no 2>/dev/null)" ]]; then
    commit="$commit (with uncommitted changes)"
fi
compiler=$(sed -n 's/^CMAKE_CXX_COMPILER:[A-Z]*=//p' "$build/CMakeCache.txt") || true
compiler_version=$("${compiler:-c++}" --version 2>/dev/null) || true
compiler_version=${compiler_version%%$'\n'*}
meta="$tmp/meta.json"
"$python" - "$meta" "$model" "$nproc" "$(date -u '+%Y-%m-%d %H:%M UTC')" "$commit" "$repeat" \
    "$compiler_version" "$quick" "${notes[@]}" <<'PY'
import json, sys
path, model, nproc, date, commit, repeat, compiler, quick, *notes = sys.argv[1:]
json.dump({"cpu": model, "nproc": int(nproc), "date": date, "commit": commit, "repeat": int(repeat),
           "compiler": compiler, "quick": quick == "1", "notes": notes}, open(path, "w"))
PY

"$python" - "$meta" "$results" "$out/results.md" <<'PY'
import json, sys
meta_path, results_path, md_path = sys.argv[1:]
meta = json.load(open(meta_path))
recs = [json.loads(l) for l in open(results_path) if l.strip()]
names = {"cmc33": "cmc33", "cmc33-mc": "cmc33 --method mc", "vtk-flying-edges": "VTK vtkFlyingEdges3D",
         "vtk-marching-cubes": "VTK vtkMarchingCubes", "skimage-lewiner": "skimage marching_cubes (lewiner)"}
MiB = 1024.0 * 1024.0

lines = ["# cmc33 against its peers: isosurface extraction", ""]
if meta["quick"]:
    lines += ["**Smoke test (--quick): small synthetic volumes and few repeats; the timings mean nothing.**", ""]
lines += [f"- date: {meta['date']}",
          f"- machine: {meta['cpu']}, {meta['nproc']} logical CPUs (nproc)",
          f"- commit: {meta['commit']}",
          f"- compiler: {meta['compiler'] or 'unknown'}, Release",
          f"- runs: median of {meta['repeat']} extraction(s) per tool and case, each tool in its own process"]
vtk = next((r for r in recs if "vtk_version" in r), None)
if vtk:
    lines.append(f"- VTK {vtk['vtk_version']}, SMP backend {vtk['smp_backend']}")
sk = next((r for r in recs if r["tool"] == "skimage-lewiner" and "version" in r), None)
if sk:
    lines.append(f"- scikit-image {sk['version']}, numpy {sk.get('numpy_version', '?')}")
lines.append("")

def fmt_ratio(rec, peer):
    if peer is None or "seconds" not in rec or "seconds" not in peer or peer["seconds"] <= 0:
        return "–"
    return f"{rec['seconds'] / peer['seconds']:.2f}"

# A peer's ratio column only where that peer ran (it is skipped when missing; the notes say why).
with_fe = any(r["tool"] == "vtk-flying-edges" for r in recs)
with_ski = any(r["tool"] == "skimage-lewiner" for r in recs)
header = ["case", "tool", "threads", "median s", "Mcells/s", "triangles", "peak RSS MiB", "input + mesh MiB"]
header += ["t / t(VTK FE 1t)"] * with_fe + ["t / t(skimage)"] * with_ski
lines.append("| " + " | ".join(header) + " |")
lines.append("|---|---|" + "--:|" * (len(header) - 2))
failures = []
seen = []
for r in recs:
    if r["case"] not in seen:
        seen.append(r["case"])
for case in seen:
    rows = [r for r in recs if r["case"] == case]
    fe1 = next((r for r in rows if r["tool"] == "vtk-flying-edges" and r.get("threads") == 1), None)
    ski = next((r for r in rows if r["tool"] == "skimage-lewiner" and "seconds" in r), None)
    for r in rows:
        d = r["dims"]
        case_text = f"{r['label']} {d[0]}x{d[1]}x{d[2]} {r['type']} iso {r['iso']:g}"
        rss = f"{r['peak_rss_kib'] / 1024:.1f}" if r.get("peak_rss_kib") is not None else "?"
        if "error" in r:
            failures.append(f"{r['label']}, {names[r['tool']]}: {r['error']}")
            cells = [case_text, names[r["tool"]], "", "failed", "", "", rss, f"{r['input_bytes'] / MiB:.1f} + –"]
            cells += [""] * with_fe + [""] * with_ski
        else:
            cells = [case_text, names[r["tool"]], str(r["threads"]), f"{r['seconds']:.4g}",
                     f"{r['mcells_per_s']:.1f}" if r.get("mcells_per_s") else "–",
                     f"{r['triangles']:,}", rss,
                     f"{r['input_bytes'] / MiB:.1f} + {r['mesh_bytes'] / MiB:.1f}"]
            cells += [fmt_ratio(r, fe1)] * with_fe + [fmt_ratio(r, ski)] * with_ski
        lines.append("| " + " | ".join(cells) + " |")
lines += ["",
          "median s: extraction alone (no file I/O), median of the runs. Mcells/s: (nx-1)(ny-1)(nz-1) cells "
          "per second, in millions. peak RSS: the whole process (GNU time %M), file reading included "
          "(the cmc33 CLI runs with --no-topology). input + mesh: the samples in memory, and "
          "12 bytes per vertex + 12 per triangle. t / t(peer): below 1 is faster than the peer. "
          "bench/README.md has the details."]
notes = meta["notes"] + [f"failed: {f}" for f in failures]
if notes:
    lines += ["", "Notes:", ""] + [f"- {n}" for n in notes]
text = "\n".join(lines) + "\n"
open(md_path, "w").write(text)
print(text, end="")
PY

echo "$prog: results in $results and $out/results.md" >&2
if ((failed > 0)); then
    die "$failed run(s) failed; the table names them"
fi
