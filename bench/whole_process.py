#!/usr/bin/python3
"""Whole processes as users time them: cmc33 extract beside VTK's and scikit-image's pipelines
(issue 36's targets).

    bench/whole_process.py [--cmc33 PATH] [--repeat N] [--json] [--noise [N]] [--no-vtk]
                           [--no-skimage] [--volumes DIR] [CASE | FILE:ISO ...]

Each of these runs in its own process, read -> extract with normals -> binary PLY, and is timed
from start to exit (wall time) with its peak resident memory (wait4's rusage):
  default      cmc33 extract V --iso X --normals -o out.ply            (checks on)
  no-topology  the same with --no-topology
  vtk          python3: vtkNrrdReader -> vtkFlyingEdges3D (normals on) -> vtkPLYWriter, binary
  skimage      python3: NRRD read into numpy (skimage_bench.read_nrrd) -> marching_cubes (lewiner)
               -> binary PLY (peer_meshes.write_ply)
The cases are aneurism, bonsai and CThead at run_bench.py's isovalues (the README's), any other
run_bench.py case named, and FILE:ISO pairs. --noise adds run_bench's noise field at N^3 (default
200, about 31 M triangles at iso 0), made with cmc33_make_field (a build with
-DCMC33_BUILD_BENCH=ON); scikit-image is left out there (it needs several GiB).

One run of each tool per case by default; --repeat N runs the tools N times in turns and reports
the medians (time) and the largest peak. Prints a Markdown table with the ratios of the targets:
default / VTK (<= 0.5), default / no-topology (<= 2; 3 on the noise field) and peak default / peak
no-topology (<= 1.3); --json prints one JSON line per case and tool instead.
Exit status: 0 all ran, 1 a run failed (named in the table) or a precondition is missing, 2 usage.
"""

import json
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from run_bench import ALL_CASES, BENCH, REPO, machine  # noqa: E402
from skimage_bench import ArgumentParser  # noqa: E402

PROG = "whole_process.py"
DEFAULT_CASES = ("aneurism", "bonsai", "CThead")
TOOLS = ("default", "no-topology", "vtk", "skimage")

# VTK as its users run it. vtkmodules rather than `import vtk`: the latter loads every module,
# and its vtkNrrdReader is the MPI one (vtkPNrrdReader), which fails without an MPI controller.
# VTK 9.1's reader leaves gzip samples in the file's byte order: argv[4] == "swap" puts them in
# the machine's, so that VTK extracts the same surface as the others (whole_process.py decides).
VTK_CHILD = r"""
import sys
from vtkmodules.vtkIOImage import vtkNrrdReader
from vtkmodules.vtkFiltersCore import vtkFlyingEdges3D
from vtkmodules.vtkIOPLY import vtkPLYWriter
reader = vtkNrrdReader()
reader.SetFileName(sys.argv[1])
if sys.argv[4] == "swap":
    from vtkmodules.vtkCommonCore import vtkByteSwap
    reader.Update()
    samples = reader.GetOutput().GetPointData().GetScalars()
    vtkByteSwap.SwapVoidRange(samples, samples.GetNumberOfValues(), samples.GetDataTypeSize())
    samples.Modified()
fe = vtkFlyingEdges3D()
fe.SetInputConnection(reader.GetOutputPort())
fe.SetValue(0, float(sys.argv[2]))
fe.ComputeNormalsOn()
fe.ComputeScalarsOff()
fe.ComputeGradientsOff()
writer = vtkPLYWriter()
writer.SetInputConnection(fe.GetOutputPort())
writer.SetFileTypeToBinary()
writer.SetFileName(sys.argv[3])
if not writer.Write():
    sys.exit("vtkPLYWriter failed")
print(fe.GetOutput().GetNumberOfPolys())
"""

# scikit-image as its users run it: the volume read into numpy, marching_cubes, a binary PLY.
SKIMAGE_CHILD = r"""
import sys
sys.path.insert(0, sys.argv[4])
from skimage_bench import read_nrrd
from peer_meshes import write_ply
from skimage.measure import marching_cubes
volume = read_nrrd(sys.argv[1])
verts, faces, _normals, _values = marching_cubes(volume, level=float(sys.argv[2]), method="lewiner")
write_ply(sys.argv[3], verts[:, ::-1], faces)
print(len(faces))
"""


def die(message):
    print(f"{PROG}: {message}", file=sys.stderr)
    sys.exit(1)


def run_measured(cmd):
    """Runs cmd and waits for it with wait4: (wall seconds, its rusage, stdout, error or None)."""
    start = time.perf_counter()
    with tempfile.TemporaryFile() as out, tempfile.TemporaryFile() as err:
        proc = subprocess.Popen(cmd, stdout=out, stderr=err)
        _, status, usage = os.wait4(proc.pid, 0)
        seconds = time.perf_counter() - start
        proc.returncode = os.waitstatus_to_exitcode(status)
        out.seek(0)
        err.seek(0)
        stdout, stderr = out.read().decode(errors="replace"), err.read().decode(errors="replace")
    if proc.returncode != 0:
        lines = [line for line in stderr.split("\n") if line.strip()]
        return seconds, usage, stdout, lines[-1] if lines else f"exited with status {proc.returncode}"
    return seconds, usage, stdout, None


def nrrd_fields(path):
    """The header fields of an attached-header NRRD file (lower-case keys), or {} for another file."""
    with open(path, "rb") as f:
        head = f.read(1 << 16)
    if not head.startswith(b"NRRD000"):
        return {}
    fields = {}
    for line in head.split(b"\n\n", 1)[0].decode("latin-1").split("\n")[1:]:
        key, sep, value = line.partition(":")
        if sep and not line.startswith("#") and ":=" not in line:
            fields[key.strip().lower()] = value.strip()
    return fields


def vtk_needs_swap(path):
    """VTK 9.1's vtkNrrdReader swaps the raw encoding's samples but not gzip's."""
    f = nrrd_fields(path)
    little = sys.byteorder == "little"
    return (f.get("encoding", "").lower() in ("gzip", "gz") and f.get("endian", "").lower() in ("big", "little")
            and (f["endian"].lower() == "little") != little)


def main(argv):
    p = ArgumentParser(prog=PROG, description=__doc__.split("\n\n")[0])
    p.add_argument("cases", nargs="*", metavar="CASE",
                   help="run_bench.py case names or FILE:ISO (default: " + ", ".join(DEFAULT_CASES) + ")")
    p.add_argument("--cmc33", default=os.path.join(REPO, "build", "cli", "cmc33"), help="the cmc33 executable")
    p.add_argument("--repeat", type=int, default=1, metavar="N", help="runs per tool, in turns; medians reported")
    p.add_argument("--json", action="store_true", help="one JSON line per case and tool instead of the table")
    p.add_argument("--noise", type=int, nargs="?", const=200, metavar="N",
                   help="add the noise field at N^3 (default 200: about 31 M triangles)")
    p.add_argument("--make-field", help="cmc33_make_field (default: beside --cmc33 in the build's bench/)")
    p.add_argument("--work", default=os.path.join(REPO, "bench-work"), help="where the noise field is kept")
    p.add_argument("--volumes", default=os.path.join(REPO, "..", "shared", "data", "volumes"), help="the real volumes")
    p.add_argument("--no-vtk", action="store_true", help="leave VTK out")
    p.add_argument("--no-skimage", action="store_true", help="leave scikit-image out")
    args = p.parse_args(argv)
    if not 1 <= args.repeat <= 100:
        p.error(f"--repeat {args.repeat} is not an integer in [1, 100]")
    if args.noise is not None and not 2 <= args.noise <= 2000:
        p.error(f"--noise {args.noise} is not an integer in [2, 2000]")
    if not os.access(args.cmc33, os.X_OK):
        die(f"{args.cmc33} is not an executable; build cmc33 or pass --cmc33 PATH")

    cases = []  # (name, file, iso)
    for c in args.cases or DEFAULT_CASES:
        if c in ALL_CASES and not ALL_CASES[c][0].startswith("work:"):
            cases.append((c, os.path.join(args.volumes, ALL_CASES[c][0]), ALL_CASES[c][1]))
            continue
        path, sep, iso = c.rpartition(":")
        try:
            cases.append((os.path.basename(path), path, float(iso)))
        except ValueError:
            sep = ""
        if not sep:
            p.error(f"\"{c}\" is neither a real-volume case of run_bench.py nor FILE:ISO")
    if args.noise is not None:
        make_field = args.make_field or os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(args.cmc33))),
                                                     "bench", "cmc33_make_field")
        noise = os.path.join(os.path.abspath(args.work), f"noise{args.noise}.nrrd")
        if not os.path.exists(noise):
            if not os.access(make_field, os.X_OK):
                die(f"{make_field} is missing: build with -DCMC33_BUILD_BENCH=ON or pass --make-field")
            os.makedirs(args.work, exist_ok=True)
            if subprocess.run([make_field, "noise", noise, str(args.noise)]).returncode != 0:
                die(f"cmc33_make_field could not write {noise}")
        cases.append((f"noise{args.noise}", noise, 0.0))
    for name, path, _ in cases:
        if not os.access(path, os.R_OK):
            die(f"case {name}: {path} is missing or unreadable")

    python = "/usr/bin/python3"
    notes = []
    tools = ["default", "no-topology"]
    if not args.no_vtk:
        if subprocess.run([python, "-c", "import vtkmodules.vtkIOPLY"], capture_output=True).returncode == 0:
            tools.append("vtk")
        else:
            notes.append(f"VTK left out: {python} cannot import vtkmodules (Debian: python3-vtk9)")
    if not args.no_skimage:
        if subprocess.run([python, "-c", "import skimage.measure"], capture_output=True).returncode == 0:
            tools.append("skimage")
        else:
            notes.append(f"scikit-image left out: {python} cannot import skimage (Debian: python3-skimage)")

    records = []
    failed = 0
    tmp = tempfile.mkdtemp(prefix="whole_process.")
    try:
        for name, path, iso in cases:
            with open(path, "rb") as f:  # into the page cache: every tool then reads it warm
                while f.read(1 << 24):
                    pass
            out = os.path.join(tmp, "out.ply")
            swap = "vtk" in tools and vtk_needs_swap(path)
            if swap:
                notes.append(f"{name}: VTK 9.1's vtkNrrdReader leaves gzip samples in the file's byte order; "
                             "the VTK run swaps them (vtkByteSwap) to extract the same surface")
            commands = {
                "default": [args.cmc33, "extract", path, "--iso", repr(iso), "--normals", "-o", out],
                "no-topology": [args.cmc33, "extract", path, "--iso", repr(iso), "--normals", "-o", out,
                                "--no-topology"],
                "vtk": [python, "-c", VTK_CHILD, path, repr(iso), out, "swap" if swap else "-"],
                "skimage": [python, "-c", SKIMAGE_CHILD, path, repr(iso), out, BENCH],
            }
            case_tools = [t for t in tools if not (t == "skimage" and name.startswith("noise"))]
            if len(case_tools) < len(tools):
                notes.append(f"{name}: scikit-image left out (several GiB)")
            runs = {t: [] for t in case_tools}
            for _ in range(args.repeat):
                for t in case_tools:
                    print(f"{PROG}: {name} {t}", file=sys.stderr, end=" ", flush=True)
                    seconds, usage, stdout, err = run_measured(commands[t])
                    rss = usage.ru_maxrss  # KiB on Linux
                    if err:
                        print(f"FAILED: {err}", file=sys.stderr)
                        runs[t].append({"error": err, "peak_rss_kib": rss})
                        continue
                    triangles = None
                    if t in ("vtk", "skimage"):
                        triangles = int(stdout.split()[-1])
                    cpu = usage.ru_utime + usage.ru_stime
                    print(f"{seconds * 1e3:.0f} ms ({cpu * 1e3:.0f} ms CPU), {rss / 1024:.0f} MiB", file=sys.stderr)
                    runs[t].append({"seconds": seconds, "cpu_seconds": cpu, "peak_rss_kib": rss, "triangles": triangles,
                                    "output_bytes": os.path.getsize(out)})
                    os.remove(out)
            for t in case_tools:
                good = not any("error" in r for r in runs[t])
                rec = {"case": name, "file": path, "iso": iso, "tool": t, "repeat": args.repeat}
                if good:
                    rec.update(seconds=statistics.median(r["seconds"] for r in runs[t]),
                               runs_seconds=[r["seconds"] for r in runs[t]],
                               cpu_seconds=statistics.median(r["cpu_seconds"] for r in runs[t]),
                               peak_rss_kib=max(r["peak_rss_kib"] for r in runs[t]),
                               output_bytes=runs[t][-1]["output_bytes"])
                    if runs[t][-1]["triangles"] is not None:
                        rec["triangles"] = runs[t][-1]["triangles"]
                else:
                    failed += 1
                    rec["error"] = next(r["error"] for r in runs[t] if "error" in r)
                records.append(rec)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)

    if args.json:
        for rec in records:
            print(json.dumps(rec))
    else:
        print(table(records, cases, machine(os.path.dirname(os.path.dirname(os.path.abspath(args.cmc33))),
                                            args.repeat, False, os.cpu_count() or 1), notes), end="")
    if failed:
        die(f"{failed} tool(s) failed; the table names them")
    return 0


def table(records, cases, meta, notes):
    def find(case, tool):
        return next((r for r in records if r["case"] == case and r["tool"] == tool and "seconds" in r), None)

    def cell(r, key, scale, digits):
        return f"{r[key] * scale:.{digits}f}" if r and key in r else "–"

    def ratio(a, b, key="seconds"):
        return f"{a[key] / b[key]:.2f}" if a and b and b[key] > 0 else "–"

    runs = "one run" if meta["repeat"] == 1 else f"the median of {meta['repeat']} runs"
    lines = ["# Whole processes: read, extract with normals, write a binary PLY", "",
             f"- date: {meta['date']}; machine: {meta['cpu']}, {meta['nproc']} logical CPUs",
             f"- commit {meta['commit']}, {meta['compiler']}, Release",
             f"- {runs}, each process timed from start to exit; peak: its largest resident memory", "",
             "| case | default s | no-topology s | VTK s | skimage s | default / VTK (≤ 0.5) | "
             "default / no-topology (≤ 2) | CPU s default / no-topology / VTK / skimage | "
             "peak MiB default / no-topology / VTK / skimage | peak default / no-topology (≤ 1.3) |",
             "|---|--:|--:|--:|--:|--:|--:|--:|--:|--:|"]
    for name, _, iso in cases:
        d, n, v, s = (find(name, t) for t in TOOLS)
        peaks = " / ".join(cell(r, "peak_rss_kib", 1 / 1024, 0) for r in (d, n, v, s))
        cpus = " / ".join(cell(r, "cpu_seconds", 1, 3) for r in (d, n, v, s))
        lines.append(f"| {name} {iso:g} | {cell(d, 'seconds', 1, 3)} | {cell(n, 'seconds', 1, 3)} | "
                     f"{cell(v, 'seconds', 1, 3)} | {cell(s, 'seconds', 1, 3)} | {ratio(d, v)} | {ratio(d, n)} | "
                     f"{cpus} | {peaks} | {ratio(d, n, 'peak_rss_kib')} |")
    lines += ["", "default: `cmc33 extract V --iso X --normals -o out.ply`; no-topology: the same with "
              "`--no-topology`; VTK: vtkNrrdReader -> vtkFlyingEdges3D (normals) -> vtkPLYWriter (binary) in "
              "python3; skimage: NRRD read into numpy -> marching_cubes (lewiner) -> binary PLY of positions "
              "and triangles (its normals are computed, not written) in python3. CPU s: user + system time of "
              "the process (all its threads); on a loaded machine it varies less than the wall time."]
    tri = [f"{r['case']} {r['tool']}: {r['triangles']:,} triangles" for r in records if "triangles" in r]
    failures = [f"failed: {r['case']}, {r['tool']}: {r['error']}" for r in records if "error" in r]
    notes = notes + tri + failures
    if notes:
        lines += ["", "Notes:", ""] + [f"- {n}" for n in notes]
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
