#!/usr/bin/python3
"""The one-invocation comparison of cmc33 with its peers, as their users run them (bench/README.md).

    bench/run_bench.py [--repeat R] [--rounds N] [--pin CPU] [--cases a,b,...] [--quick] [--out DIR]
                       [--volumes DIR] [--build DIR] [--work DIR] [--no-skimage]

Builds cmc33 (Release, -DCMC33_BUILD_BENCH=ON), makes the synthetic volumes, and on every case runs,
each in its own process under GNU time (peak memory):
  * cmc33 extract --normals, 1 thread and all cores; and without normals, 1 thread
  * vtkFlyingEdges3D through VTK's Python wrapping (vtk_bench.py), normals on, 1 thread and all
    cores; and normals off, 1 thread
  * scikit-image's marching_cubes (lewiner), which always computes normals (skimage_bench.py)
  * cmc33_read_floor: the time to read the volume's bytes from memory (hot, and at the bandwidth
    of a buffer larger than the caches), the floor under any extractor
and writes OUT/results.jsonl and the Markdown tables OUT/results.md (also printed).
Exit status: 0 all ran, 1 some run failed (the table names it) or a precondition is missing.
"""

import argparse
import json
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

PROG = "run_bench.py"
REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
BENCH = os.path.join(REPO, "bench")

# name: (file: a name alone is in --volumes, "work:" is a synthetic volume made by cmc33_make_field,
# isovalue, why). Half-integer isovalues on integer data, so that no tie changes any tool's work,
# plus one integer isovalue (aneurism-80), where the sign rule of each tool decides the ties.
CASES = {
    "aneurism": ("aneurism_256x256x256_uint8.nrrd", 80.5, "vessels (README: 80 is common)"),
    "aneurism-80": ("aneurism_256x256x256_uint8.nrrd", 80.0, "the same at an integer isovalue: ties"),
    "bonsai": ("bonsai_256x256x256_uint8.nrrd", 40.5, "tree, README range 30-50"),
    "engine": ("engine_256x256x128_uint8.nrrd", 80.5, "block surface, README range 60-100"),
    "CThead": ("CThead_256x256x113_uint16.nrrd", 650.5, "skin, README 600-700 (big-endian, gzip)"),
    "mri_head": ("mri_head_256x256x256_uint8.nrrd", 40.5, "head surface, README 30-45 (gzip)"),
    "stent": ("stent_128x128x256_int16.nrrd", 250.5, "contrast-filled vessels, README 200-300"),
    "stagbeetle": ("stagbeetle_138x138x82_uint16.nrrd", 800.5, "exoskeleton, README 600-1200: rough, many decided cells"),
    "silicium": ("silicium_98x34x34_uint8.nrrd", 100.5, "lattice, README 70-150: a small volume, a dense surface"),
    "nucleon": ("nucleon_41x41x41_uint8.nrrd", 100.5, "41^3, README 50-150: where the per-extraction costs weigh"),
    "Bucky": ("Bucky_32x32x32_uint8.nrrd", 51.5, "32^3, the C60 cage at the CUDA sample's level (about 51)"),
    "sphere": ("work:sphere", 0.0, "distance field: one smooth sphere, few cells crossed"),
    "sines": ("work:sines", 0.25, "a large smooth surface over the whole grid"),
    "noise": ("work:noise", 0.0, "the worst case: nearly every cell crossed, most ambiguous"),
    "ties": ("work:ties", 80.0, "{60, 80, 100} as float32 at iso 80: ties everywhere, exact decisions"),
    "ties-u8": ("work:ties-u8", 80.0, "the same numbers as uint8"),
}
# More real volumes, run only when --cases names them (--cases more: all of these): the rest of
# ../shared/data/volumes at isovalues from its README, and other surfaces of the default cases'
# volumes, to check that the default cases' ratios are not theirs alone.
MORE_CASES = {
    "tooth": ("tooth_103x94x161_uint8.nrrd", 120.5, "tooth surface, README 110-130"),
    "headsq-skin": ("headsq_quarter_64x64x93_uint16.nrrd", 500.5, "VTK textbook skin at 500; spacing 3.2 3.2 1.5"),
    "headsq-bone": ("headsq_quarter_64x64x93_uint16.nrrd", 1150.5, "VTK textbook bone at 1150"),
    "ironProt": ("ironProt_68x68x68_uint8.nrrd", 96.5, "README 64-128"),
    "neghip": ("neghip_66x66x66_uint8.nrrd", 90.5, "README 60-130"),
    "HeadMRVolume": ("HeadMRVolume_48x62x42_uint8.nrrd", 40.5, "head surface about 40; spacing 4 4 4"),
    "LIDC2-body": ("LIDC2_256x256x133_uint8.nrrd", 60.5, "chest CT body surface about 60 (gzip)"),
    "LIDC2-bone": ("LIDC2_256x256x133_uint8.nrrd", 150.5, "chest CT bone about 150"),
    "walnut": ("walnut_128x96x114_uint16.nrrd", 5000.5, "shell and kernel, README 4000-7600"),
    "Cranium-skin": ("Cranium_256x256x108_int16.nrrd", -400.5, "head CT in Hounsfield units, skin (gzip)"),
    "Cranium-bone": ("Cranium_256x256x108_int16.nrrd", 400.5, "skull and teeth"),
    "ch2-head": ("ch2_181x217x181_uint8.nrrd", 30.5, "T1 MRI head surface, README 25-40 (gzip)"),
    "ch2-brain": ("ch2_181x217x181_uint8.nrrd", 90.5, "white/grey matter boundary, README about 90"),
    "bonsai-pot": ("bonsai_256x256x256_uint8.nrrd", 150.5, "pot and soil, README 120-200"),
    "engine-inner": ("engine_256x256x128_uint8.nrrd", 180.5, "dense inner parts, README 170-200"),
    "mri_head-brain": ("mri_head_256x256x256_uint8.nrrd", 85.5, "brain tissue, README 80-90 (gzip)"),
    "aneurism-120": ("aneurism_256x256x256_uint8.nrrd", 120.0, "a second integer isovalue"),
    "CThead-bone": ("CThead_256x256x113_uint16.nrrd", 1500.5, "bone, README 1400-1600"),
}
ALL_CASES = {**CASES, **MORE_CASES}
SIZES = {"sphere": (256, 64), "sines": (512, 128), "noise": (128, 64), "ties": (128, 64), "ties-u8": (128, 64)}  # full, --quick
TYPE_BYTES = {"int8": 1, "uint8": 1, "int16": 2, "uint16": 2, "int32": 4, "uint32": 4, "float": 4, "double": 8}


def die(message):
    print(f"{PROG}: {message}", file=sys.stderr)
    sys.exit(1)


class ArgumentParser(argparse.ArgumentParser):
    def error(self, message):
        print(f"{PROG}: {message} (try --help)", file=sys.stderr)
        sys.exit(2)


def run_tool(cmd, tmp):
    """Runs cmd under GNU time; returns (parsed JSON or None, peak RSS KiB or None, error or None)."""
    rss_path = os.path.join(tmp, "rss")
    proc = subprocess.run(["/usr/bin/time", "-f", "%M", "-o", rss_path, "--"] + cmd,
                          stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    rss = None
    try:
        for line in reversed(open(rss_path).read().split("\n")):
            if line.strip().isdigit():
                rss = int(line)
                break
    except OSError:
        pass
    if proc.returncode != 0:
        lines = [l for l in proc.stderr.split("\n") if l.strip()]
        why = lines[-1] if lines else f"exited with status {proc.returncode}"
        return None, rss, why
    try:  # cmc33 prints one indented JSON document, the Python drivers one line
        return json.loads(proc.stdout), rss, None
    except ValueError:
        pass
    try:
        return json.loads(proc.stdout.strip().split("\n")[-1]), rss, None
    except (ValueError, IndexError):
        return None, rss, "printed no JSON result: " + proc.stdout.strip()[:200]


def main(argv):
    p = ArgumentParser(prog=PROG, description=__doc__.split("\n\n")[0])
    p.add_argument("--repeat", type=int, help="extractions per tool and case; the median is reported (default 5; --quick 1)")
    p.add_argument("--cases", help="comma-separated cases (default: " + ",".join(CASES) + "); also "
                                   + ",".join(MORE_CASES) + ", or \"more\" for all of those")
    p.add_argument("--quick", action="store_true", help="smoke test: small synthetic volumes, 1 repeat")
    p.add_argument("--out", help="where results.jsonl, results.md and build.log go (default WORK/results)")
    p.add_argument("--volumes", default=os.path.join(REPO, "..", "shared", "data", "volumes"),
                   help="the real volumes (default ../shared/data/volumes beside the repository)")
    p.add_argument("--build", default=os.path.join(REPO, "build-bench"), help="the build folder (default build-bench)")
    p.add_argument("--work", default=os.path.join(REPO, "bench-work"),
                   help="where the synthetic volumes are made and kept (default bench-work)")
    p.add_argument("--no-skimage", action="store_true", help="leave scikit-image out (its runs are the slow ones)")
    p.add_argument("--rounds", type=int, default=1,
                   help="run every tool of a case this many times, the tools taking turns, and report the median "
                        "of the rounds' medians (default 1): on a VM whose speed drifts, every tool samples the "
                        "same drift")
    p.add_argument("--pin", type=int, metavar="CPU",
                   help="run the one-thread runs of every tool under taskset -c CPU (the same CPU for all tools: "
                        "on a VM whose vCPUs differ in speed, they compare on one)")
    args = p.parse_args(argv)
    repeat = args.repeat if args.repeat is not None else (1 if args.quick else 5)
    if not 1 <= repeat <= 1000:
        p.error(f"--repeat {repeat} is not an integer in [1, 1000]")
    if not 1 <= args.rounds <= 100:
        p.error(f"--rounds {args.rounds} is not an integer in [1, 100]")
    if args.pin is not None and not 0 <= args.pin < (os.cpu_count() or 1):
        p.error(f"--pin {args.pin} is not a CPU of this machine (0 to {(os.cpu_count() or 1) - 1})")
    if args.pin is not None and shutil.which("taskset") is None:
        p.error("--pin needs taskset (Debian: util-linux)")
    cases = list(CASES) if not args.cases else [c.strip() for c in args.cases.split(",") if c.strip()]
    cases = [m for c in cases for m in (MORE_CASES if c == "more" else [c])]
    for c in cases:
        if c not in ALL_CASES:
            p.error(f"unknown case \"{c}\"; expected some of {','.join(ALL_CASES)} or more")
    if not cases:
        p.error("--cases is empty")
    out = args.out or os.path.join(args.work, "results")

    # ---- preconditions ---------------------------------------------------------------------
    if "GNU" not in subprocess.run(["/usr/bin/time", "--version"], capture_output=True, text=True).stderr + \
            subprocess.run(["/usr/bin/time", "--version"], capture_output=True, text=True).stdout \
            if os.path.exists("/usr/bin/time") else True:
        die("GNU time (/usr/bin/time) is missing; it measures the peak memory: apt-get install time "
            "(or scripts/install-deps.sh --bench)")
    for tool in ("cmake", "ninja"):
        if shutil.which(tool) is None:
            die(f"{tool} is missing (scripts/install-deps.sh installs it)")
    files = {}
    for c in cases:
        f = ALL_CASES[c][0]
        if f.startswith("work:"):
            kind = f[5:]
            n = SIZES[kind][1 if args.quick else 0]
            files[c] = os.path.join(os.path.abspath(args.work), f"{kind}{n}.nrrd")
        else:
            path = os.path.join(args.volumes, f)
            if not os.access(path, os.R_OK):
                die(f"case {c}: {path} is missing or unreadable; pass --volumes DIR or choose --cases")
            files[c] = os.path.abspath(path)
    python = sys.executable
    notes = []
    have_vtk = subprocess.run([python, "-c", "import vtk"], capture_output=True).returncode == 0
    if not have_vtk:
        notes.append(f"VTK columns empty: {python} cannot import vtk (Debian: apt-get install python3-vtk9)")
    have_skimage = not args.no_skimage and \
        subprocess.run([python, "-c", "import skimage.measure"], capture_output=True).returncode == 0
    if not have_skimage:
        notes.append("scikit-image column empty: " + ("--no-skimage" if args.no_skimage else
                     f"{python} cannot import skimage (Debian: apt-get install python3-skimage)"))

    # ---- build ---------------------------------------------------------------------------
    os.makedirs(out, exist_ok=True)
    os.makedirs(args.work, exist_ok=True)
    log_path = os.path.join(out, "build.log")
    print(f"{PROG}: building in {args.build} (log: {log_path})", file=sys.stderr)
    with open(log_path, "w") as log:
        for cmd in (["cmake", "-S", REPO, "-B", args.build, "-G", "Ninja", "-DCMAKE_BUILD_TYPE=Release",
                     "-DCMC33_BUILD_BENCH=ON"],
                    ["ninja", "-C", args.build, "cmc33_cli", "cmc33_make_field", "cmc33_read_floor"]):
            if subprocess.run(cmd, stdout=log, stderr=subprocess.STDOUT).returncode != 0:
                die(f"the build failed; see {log_path}")
    cmc33 = os.path.join(args.build, "cli", "cmc33")
    make_field = os.path.join(args.build, "bench", "cmc33_make_field")
    read_floor = os.path.join(args.build, "bench", "cmc33_read_floor")

    for c in cases:
        f = files[c]
        if ALL_CASES[c][0].startswith("work:") and not (os.path.exists(f) and os.path.getmtime(f) >= os.path.getmtime(make_field)):
            kind = ALL_CASES[c][0][5:]
            n = SIZES[kind][1 if args.quick else 0]
            print(f"{PROG}: making {f}", file=sys.stderr)
            field = ["ties", f, str(n), "--uint8"] if kind == "ties-u8" else [kind, f, str(n)]
            if subprocess.run([make_field] + field).returncode != 0:
                die(f"cmc33_make_field could not write {f}")

    # ---- the runs ------------------------------------------------------------------------
    nproc = os.cpu_count() or 1
    # (tool, threads: 0 = all cores, normals)
    runs = [("cmc33", 1, True), ("vtk-fe", 1, True)]
    if nproc > 1:
        runs += [("cmc33", 0, True), ("vtk-fe", 0, True)]
    runs += [("cmc33", 1, False), ("vtk-fe", 1, False)]
    if have_skimage:
        runs.append(("skimage", 1, True))
    if not have_vtk:
        runs = [r for r in runs if r[0] != "vtk-fe"]
    results_path = os.path.join(out, "results.jsonl")
    records = []
    failed = 0
    tmp = tempfile.mkdtemp()
    try:
        total = len(cases) * (args.rounds * len(runs) + 1)
        step = 0
        for c in cases:
            f, iso = files[c], ALL_CASES[c][1]
            info = subprocess.run([cmc33, "info", f, "--json"], capture_output=True, text=True)
            if info.returncode != 0:
                die(f"case {c}: cmc33 info cannot read {f}: {info.stderr.strip()}")
            info = json.loads(info.stdout)
            dims, vtype = info["dims"], info["type"]
            nbytes = dims[0] * dims[1] * dims[2] * TYPE_BYTES[vtype]
            base = {"case": c, "file": f, "iso": iso, "dims": dims, "type": vtype, "input_bytes": nbytes}
            step += 1
            print(f"{PROG}: [{step}/{total}] {c:12} read floor", file=sys.stderr, end=" ")
            floor, _, err = run_tool([read_floor, str(nbytes)], tmp)
            records.append(dict(base, tool="floor", **(floor or {"error": err})))
            print(f"hot {floor['hot_seconds'] * 1e3:.2f} ms, cold {floor['cold_seconds'] * 1e3:.2f} ms"
                  if floor else f"FAILED: {err}", file=sys.stderr)
            done = {}  # (tool, threads, normals) -> the record of its rounds so far
            for rnd, (tool, threads, normals) in [(n, run) for n in range(args.rounds) for run in runs]:
                step += 1
                if tool == "cmc33":
                    cmd = [cmc33, "extract", f, "--iso", repr(iso), "--json", "--no-topology", "--quiet",
                           "--repeat", str(repeat), "--threads", str(threads)] + (["--normals"] if normals else [])
                elif tool == "vtk-fe":
                    cmd = [python, os.path.join(BENCH, "vtk_bench.py"), f, repr(iso), "--repeat", str(repeat),
                           "--threads", str(threads)] + ([] if normals else ["--no-normals"])
                else:
                    cmd = [python, os.path.join(BENCH, "skimage_bench.py"), f, repr(iso), "--repeat", str(repeat)]
                if args.pin is not None and threads == 1:
                    cmd = ["taskset", "-c", str(args.pin)] + cmd
                label = f"{tool} {'all' if threads == 0 else threads}t {'normals' if normals else 'no normals'}"
                if args.rounds > 1:
                    label += f" r{rnd + 1}"
                print(f"{PROG}: [{step}/{total}] {c:12} {label:31}", file=sys.stderr, end=" ")
                r, rss, err = run_tool(cmd, tmp)
                rec = done.get((tool, threads, normals))
                if rec is None:
                    rec = done[(tool, threads, normals)] = dict(base, tool=tool, normals=normals, requested_threads=threads,
                                                                peak_rss_kib=None, rounds_seconds=[], runs_seconds=[],
                                                                first_seconds=[])
                    records.append(rec)
                if rss is not None:
                    rec["peak_rss_kib"] = max(rec["peak_rss_kib"] or 0, rss)
                if err:
                    if "error" not in rec:
                        failed += 1
                    rec["error"] = err
                    print(f"FAILED: {err}", file=sys.stderr)
                    continue
                rec["rounds_seconds"].append(r["seconds"])
                rec["runs_seconds"] += r.get("runs_seconds", [])
                if r.get("runs_seconds"):
                    rec["first_seconds"].append(r["runs_seconds"][0])  # the process's first extraction
                rec.update({k: r[k] for k in ("vertices", "triangles", "threads") if k in r})
                for k in ("smp_backend", "vtk_version", "version", "numpy_version"):
                    if k in r:
                        rec[k] = r[k]
                print(f"{r['seconds'] * 1e3:.1f} ms, {r['triangles']} triangles, "
                      f"{(rss or 0) / 1024:.0f} MiB peak", file=sys.stderr)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    for rec in records:
        # the median of the rounds' medians; a tool that failed in any round is marked failed in the table
        if rec.get("rounds_seconds") and "error" not in rec:
            rec["seconds"] = statistics.median(rec["rounds_seconds"])
            if rec.get("first_seconds"):
                rec["first_run_seconds"] = statistics.median(rec["first_seconds"])
    with open(results_path, "w") as fp:
        for rec in records:
            fp.write(json.dumps(rec) + "\n")
    meta = machine(args.build, repeat, args.quick, nproc)
    meta.update(rounds=args.rounds, pin=args.pin)
    text = tables(records, cases, meta, notes)
    with open(os.path.join(out, "results.md"), "w") as fp:
        fp.write(text)
    print(text, end="")
    print(f"{PROG}: results in {results_path} and {os.path.join(out, 'results.md')}", file=sys.stderr)
    if failed:
        die(f"{failed} run(s) failed; the table names them")
    return 0


def machine(build, repeat, quick, nproc):
    model = "unknown"
    try:
        for line in subprocess.run(["lscpu"], capture_output=True, text=True).stdout.split("\n"):
            if line.startswith("Model name:"):
                model = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    commit = subprocess.run(["git", "-C", REPO, "rev-parse", "--short", "HEAD"], capture_output=True, text=True).stdout.strip()
    dirty = subprocess.run(["git", "-C", REPO, "status", "--porcelain", "--untracked-files=no"],
                           capture_output=True, text=True).stdout.strip()
    compiler = "unknown"
    try:
        for line in open(os.path.join(build, "CMakeCache.txt")):
            if line.startswith("CMAKE_CXX_COMPILER:"):
                cxx = line.split("=", 1)[1].strip()
                compiler = subprocess.run([cxx, "--version"], capture_output=True, text=True).stdout.split("\n")[0]
    except OSError:
        pass
    return {"cpu": model, "nproc": nproc, "date": time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()),
            "commit": (commit or "unknown") + (" (with uncommitted changes)" if dirty else ""),
            "compiler": compiler, "repeat": repeat, "quick": quick}


def tables(records, cases, meta, notes):
    def find(case, tool, threads=1, normals=True):
        for r in records:
            if r["case"] == case and r["tool"] == tool and (tool == "floor" or
                                                             (r.get("requested_threads") == threads and r.get("normals") == normals)):
                return r
        return None

    def ms(r, key="seconds"):
        """r[key] in ms; "failed" for a run that gave no time at all."""
        if r and key in r:
            return f"{r[key] * 1e3:.1f}"
        return "failed" if r and "seconds" not in r else "–"

    def ratio(a, b, key="seconds"):
        if not a or not b or key not in a or key not in b or b[key] <= 0:
            return "–"
        return f"{a[key] / b[key]:.2f}"

    def mib(r):
        return f"{r['peak_rss_kib'] / 1024:.0f}" if r and r.get("peak_rss_kib") else "–"

    vtk = next((r for r in records if "vtk_version" in r), None)
    ski = next((r for r in records if r["tool"] == "skimage" and "version" in r), None)
    lines = ["# cmc33 against its peers", ""]
    if meta["quick"]:
        lines += ["**Smoke test (--quick): small synthetic volumes, 1 repeat; the timings mean nothing.**", ""]
    lines += [f"- date: {meta['date']}; machine: {meta['cpu']}, {meta['nproc']} logical CPUs",
              f"- commit {meta['commit']}, {meta['compiler']}, Release",
              f"- every figure: the median of {meta['repeat']} extractions (file reading excluded), each tool in its own process"]
    if meta.get("rounds", 1) > 1:
        lines += [f"- {meta['rounds']} rounds, the tools of a case taking turns: every figure is the median of the rounds' medians"]
    if meta.get("pin") is not None:
        lines += [f"- one-thread runs of every tool pinned to CPU {meta['pin']} (taskset -c {meta['pin']})"]
    if vtk:
        lines.append(f"- VTK {vtk['vtk_version']} through its Python wrapping, vtkSMPTools backend {vtk['smp_backend']}")
    if ski:
        lines.append(f"- scikit-image {ski['version']}, numpy {ski.get('numpy_version', '?')}")
    lines += ["", "## Normals on for every tool", "",
              "| case | triangles cmc33 / FE | cmc33 1t ms | FE 1t ms | cmc33 / FE | cmc33 all ms | FE all ms | "
              "cmc33 / FE | speed-up cmc33 / FE | skimage ms | read floor hot / cold ms | cmc33 1t / cold floor | "
              "peak MiB cmc33 / FE / skimage |",
              "|---|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|"]
    failures = [f"{r['case']}, {r['tool']}: {r['error']}" for r in records if "error" in r]
    for c in cases:
        r0 = next(r for r in records if r["case"] == c)
        d = r0["dims"]
        name = f"{c} {d[0]}x{d[1]}x{d[2]} {r0['type']}, iso {r0['iso']:g}"
        a1, f1 = find(c, "cmc33", 1), find(c, "vtk-fe", 1)
        aa, fa = find(c, "cmc33", 0), find(c, "vtk-fe", 0)
        sk, fl = find(c, "skimage"), find(c, "floor")
        tri = f"{a1['triangles']:,} / {f1['triangles']:,}" if a1 and f1 and "triangles" in a1 and "triangles" in f1 else "–"
        speedup = "–"
        if a1 and aa and f1 and fa and all("seconds" in r for r in (a1, aa, f1, fa)):
            speedup = f"{a1['seconds'] / aa['seconds']:.2f} / {f1['seconds'] / fa['seconds']:.2f}"
        floor = f"{fl['hot_seconds'] * 1e3:.2f} / {fl['cold_seconds'] * 1e3:.2f}" if fl and "hot_seconds" in fl else "–"
        multiple = f"{a1['seconds'] / fl['cold_seconds']:.0f}×" if a1 and "seconds" in a1 and fl and "cold_seconds" in fl else "–"
        lines.append(f"| {name} | {tri} | {ms(a1)} | {ms(f1)} | {ratio(a1, f1)} | {ms(aa)} | {ms(fa)} | {ratio(aa, fa)} | "
                     f"{speedup} | {ms(sk)} | {floor} | {multiple} | {mib(a1)} / {mib(f1)} / {mib(sk)} |")
    lines += ["", "## Normals off (cmc33 and Flying Edges; scikit-image cannot turn them off)", "",
              "| case | cmc33 1t ms | FE 1t ms | cmc33 / FE | peak MiB cmc33 / FE |", "|---|--:|--:|--:|--:|"]
    for c in cases:
        a, f = find(c, "cmc33", 1, False), find(c, "vtk-fe", 1, False)
        lines.append(f"| {c} | {ms(a)} | {ms(f)} | {ratio(a, f)} | {mib(a)} / {mib(f)} |")
    if meta["repeat"] > 1:
        lines += ["", "## The first extraction in each process (one thread, normals)", "",
                  "What one `cmc33 extract` call, or one Update() of a new VTK pipeline, costs once the volume is "
                  "read: the first extraction of each process (the median over the rounds), from the runs above. "
                  "It writes memory the process has not used before; the later ones reuse it.", "",
                  "| case | cmc33 1t ms | FE 1t ms | cmc33 / FE | all runs (above) cmc33 / FE ms |", "|---|--:|--:|--:|--:|"]
        for c in cases:
            a, f = find(c, "cmc33", 1), find(c, "vtk-fe", 1)
            first = "first_run_seconds"
            lines.append(f"| {c} | {ms(a, first)} | {ms(f, first)} | {ratio(a, f, first)} | {ms(a)} / {ms(f)} |")
    lines += ["",
              "FE: vtkFlyingEdges3D. 1t: one thread; all: every core (cmc33 --threads 0, vtkSMPTools' default). "
              "cmc33 / FE below 1 is faster than Flying Edges. speed-up: 1-thread time over all-cores time. "
              "Read floor: reading the volume's bytes once by one core, hot (just read, in cache if it fits) and "
              "cold (at the bandwidth of a buffer larger than the caches); cmc33 1t / cold floor is how many "
              "such reads the extraction takes. Peak MiB: the whole process (GNU time %M), the Python "
              "interpreter and its modules included for VTK and scikit-image. bench/README.md has the details."]
    tf, tu = find("ties", "cmc33", 1), find("ties-u8", "cmc33", 1)
    if tf and tu and "seconds" in tf and "seconds" in tu:
        lines += ["", f"Ties: cmc33 on the float32 ties field takes {tf['seconds'] / tu['seconds']:.2f}x its time on the "
                      "same numbers as uint8 (one thread, normals)."]
    notes = notes + [f"failed: {f}" for f in failures]
    if notes:
        lines += ["", "Notes:", ""] + [f"- {n}" for n in notes]
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
