#!/usr/bin/python3
"""Whole processes on label maps: cmc33 labels beside VTK's vtkDiscreteFlyingEdges3D and one
cmc33 extract of the same map's foreground (docs/labels.md's targets).

    bench/labels_bench.py [--cmc33 PATH] [--volumes DIR] [--work DIR] [--no-vtk] [--without-normals] [--json] [CASE ...]

Makes the label maps from the shared volumes (kept in --work, made once), as uint8/uint16 NRRD:
  CThead    tissue classes by thresholds 600 and 1400 (as tests/labels/test_labels_volumes.cpp)
  aneurism  the connected components (6-neighbours, scipy.ndimage.label) of the samples >= 80.5
  bonsai    classes by thresholds 40.5 (tree) and 150.5 (pot and soil), run_bench.py's isovalues
and runs each of these in its own process, once, timed from start to exit (wall time) with its
peak resident memory:
  labels-1   cmc33 labels SEG -o DIR --normals --threads 1   (every label but 0, one PLY per label)
  labels     cmc33 labels SEG -o DIR --normals                (threads: all cores)
             (--without-normals drops --normals, to see what the normals cost)
  vtk-1      python3: vtkNrrdReader -> vtkDiscreteFlyingEdges3D (every label but 0, ComputeNormals
             on) -> vtkPLYWriter (binary, one file), vtkSMPTools at 1 thread
  vtk        the same at VTK's default thread count (all cores)
  extract-1  cmc33 extract SEG --iso 0.5 --normals -o out.ply --threads 1   (the foreground)
  extract    the same with all cores
Prints a Markdown table with the ratios of the targets: labels / VTK (<= 0.5) and labels / extract
(<= 3), each at one thread and at all cores; --json prints one JSON line per case and tool instead.
Exit status: 0 all ran, 1 a run failed (named) or a precondition is missing, 2 usage.
"""

import json
import os
import shutil
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from run_bench import REPO, machine  # noqa: E402
from skimage_bench import ArgumentParser, ReadError, read_nrrd  # noqa: E402
from whole_process import run_measured  # noqa: E402

PROG = "labels_bench.py"
TOOLS = ("labels-1", "labels", "vtk-1", "vtk", "extract-1", "extract")

# name: (shared volume, how its label map is made, the argument)
CASES = {
    "CThead": ("CThead_256x256x113_uint16.nrrd", "classes", (600, 1400)),
    "aneurism": ("aneurism_256x256x256_uint8.nrrd", "components", 80.5),
    "bonsai": ("bonsai_256x256x256_uint8.nrrd", "classes", (40.5, 150.5)),
}

# VTK as its users run it on a label map: every label but the background contoured by
# vtkDiscreteFlyingEdges3D with its normals, one binary PLY. argv: SEG OUT THREADS LABELS...
VTK_CHILD = r"""
import sys
from vtkmodules.vtkCommonCore import vtkSMPTools
from vtkmodules.vtkIOImage import vtkNrrdReader
from vtkmodules.vtkFiltersGeneral import vtkDiscreteFlyingEdges3D
from vtkmodules.vtkIOPLY import vtkPLYWriter
threads = int(sys.argv[3])
if threads > 0:
    vtkSMPTools.Initialize(threads)
else:
    vtkSMPTools.Initialize()
reader = vtkNrrdReader()
reader.SetFileName(sys.argv[1])
fe = vtkDiscreteFlyingEdges3D()
fe.SetInputConnection(reader.GetOutputPort())
for n, label in enumerate(sys.argv[4:]):
    fe.SetValue(n, float(label))
fe.ComputeNormalsOn()
fe.ComputeScalarsOn()
fe.ComputeGradientsOff()
writer = vtkPLYWriter()
writer.SetInputConnection(fe.GetOutputPort())
writer.SetFileTypeToBinary()
writer.SetFileName(sys.argv[2])
if not writer.Write():
    sys.exit("vtkPLYWriter failed")
print(fe.GetOutput().GetNumberOfPolys())
"""


def die(message):
    print(f"{PROG}: {message}", file=sys.stderr)
    sys.exit(1)


def write_nrrd(path, labels):
    """A raw little-endian NRRD of `labels` (z, y, x), written whole to a temporary name first."""
    import numpy as np

    kind = {np.dtype(np.uint8): "uint8", np.dtype(np.uint16): "uint16"}[labels.dtype]
    z, y, x = labels.shape
    header = (f"NRRD0004\ntype: {kind}\ndimension: 3\nsizes: {x} {y} {z}\nencoding: raw\nendian: little\n"
              "spacings: 1 1 1\n\n")
    tmp = path + ".part"
    with open(tmp, "wb") as f:
        f.write(header.encode("ascii"))
        f.write(labels.astype(labels.dtype.newbyteorder("<"), copy=False).tobytes())
    os.replace(tmp, path)


def make_label_map(volumes, work, name):
    """The case's label map file (made once) and its labels other than 0."""
    import numpy as np

    source, how, arg = CASES[name]
    path = os.path.join(work, f"{name}_labels.nrrd")
    labels_file = path + ".labels"
    if not (os.path.exists(path) and os.path.exists(labels_file)):
        try:
            v = read_nrrd(os.path.join(volumes, source))
        except ReadError as e:
            die(str(e))
        if how == "classes":
            seg = np.zeros(v.shape, np.uint8)
            for t in arg:
                seg += (v >= t).astype(np.uint8)
        else:
            from scipy import ndimage

            seg, count = ndimage.label(v >= arg)
            seg = seg.astype(np.uint16 if count < 65536 else np.uint32)
        os.makedirs(work, exist_ok=True)
        write_nrrd(path, seg)
        present = [int(x) for x in np.unique(seg) if x != 0]
        with open(labels_file, "w") as f:
            f.write(" ".join(map(str, present)) + "\n")
    with open(labels_file) as f:
        return path, f.read().split()


def main(argv):
    p = ArgumentParser(prog=PROG, description=__doc__.split("\n\n")[0])
    p.add_argument("cases", nargs="*", metavar="CASE", help="of " + ", ".join(CASES) + " (default: all)")
    p.add_argument("--cmc33", default=os.path.join(REPO, "build", "cli", "cmc33"), help="the cmc33 executable")
    p.add_argument("--volumes", default=os.path.join(REPO, "..", "shared", "data", "volumes"), help="the real volumes")
    p.add_argument("--work", default=os.path.join(REPO, "bench-work"), help="where the label maps are kept")
    p.add_argument("--no-vtk", action="store_true", help="leave VTK out")
    p.add_argument("--without-normals", action="store_true",
                   help="cmc33 labels without --normals (VTK and extract keep theirs)")
    p.add_argument("--json", action="store_true", help="one JSON line per case and tool instead of the table")
    args = p.parse_args(argv)
    for c in args.cases:
        if c not in CASES:
            p.error(f"\"{c}\" is not a case; expected one of " + ", ".join(CASES))
    if not os.access(args.cmc33, os.X_OK):
        die(f"{args.cmc33} is not an executable; build cmc33 or pass --cmc33 PATH")
    python = "/usr/bin/python3"
    # issue #39's target is stated with normals on, as VTK computes them
    normals = [] if args.without_normals else ["--normals"]
    tools = list(TOOLS)
    notes = []
    if args.no_vtk:
        tools = [t for t in tools if not t.startswith("vtk")]
    elif subprocess.run([python, "-c", "import vtkmodules.vtkFiltersGeneral"], capture_output=True).returncode != 0:
        tools = [t for t in tools if not t.startswith("vtk")]
        notes.append(f"VTK left out: {python} cannot import vtkmodules (Debian: python3-paraview or python3-vtk9)")

    records = []
    failed = 0
    tmp = tempfile.mkdtemp(prefix="labels_bench.")
    try:
        for name in args.cases or CASES:
            seg, present = make_label_map(args.volumes, args.work, name)
            with open(seg, "rb") as f:  # into the page cache: every tool then reads it warm
                while f.read(1 << 24):
                    pass
            out_dir, out_ply = os.path.join(tmp, "labels"), os.path.join(tmp, "out.ply")
            commands = {
                "labels-1": [args.cmc33, "labels", seg, "-o", out_dir, "--threads", "1"] + normals,
                "labels": [args.cmc33, "labels", seg, "-o", out_dir] + normals,
                "vtk-1": [python, "-c", VTK_CHILD, seg, out_ply, "1"] + present,
                "vtk": [python, "-c", VTK_CHILD, seg, out_ply, "0"] + present,
                "extract-1": [args.cmc33, "extract", seg, "--iso", "0.5", "--normals", "-o", out_ply, "--threads", "1"],
                "extract": [args.cmc33, "extract", seg, "--iso", "0.5", "--normals", "-o", out_ply],
            }
            for t in tools:
                print(f"{PROG}: {name} {t}", file=sys.stderr, end=" ", flush=True)
                seconds, usage, stdout, err = run_measured(commands[t])
                rec = {"case": name, "labels": len(present), "tool": t, "peak_rss_kib": usage.ru_maxrss}
                if err:
                    print(f"FAILED: {err}", file=sys.stderr)
                    rec["error"] = err
                    failed += 1
                else:
                    cpu = usage.ru_utime + usage.ru_stime
                    size = (sum(os.path.getsize(os.path.join(out_dir, f)) for f in os.listdir(out_dir))
                            if t.startswith("labels") else os.path.getsize(out_ply))
                    print(f"{seconds * 1e3:.0f} ms ({cpu * 1e3:.0f} ms CPU)", file=sys.stderr)
                    rec.update(seconds=seconds, cpu_seconds=cpu, output_bytes=size)
                    if t.startswith("vtk"):
                        rec["triangles"] = int(stdout.split()[-1])
                records.append(rec)
                shutil.rmtree(out_dir, ignore_errors=True)
                if os.path.exists(out_ply):
                    os.remove(out_ply)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)

    if args.json:
        for rec in records:
            print(json.dumps(rec))
    else:
        meta = machine(os.path.dirname(os.path.dirname(os.path.abspath(args.cmc33))), 1, False, os.cpu_count() or 1)
        print(table(records, args.cases or list(CASES), meta, notes, not args.without_normals), end="")
    if failed:
        die(f"{failed} run(s) failed; the table names them")
    return 0


def table(records, cases, meta, notes, normals):
    def find(case, tool):
        return next((r for r in records if r["case"] == case and r["tool"] == tool and "seconds" in r), None)

    def secs(r):
        return f"{r['seconds']:.2f}" if r else "–"

    def ratio(a, b, key="seconds"):
        return f"{a[key] / b[key]:.2f}" if a and b and b[key] > 0 else "–"

    lines = ["# Label maps: whole processes, read -> surfaces -> files", "",
             f"- date: {meta['date']}; machine: {meta['cpu']}, {meta['nproc']} logical CPUs",
             f"- commit {meta['commit']}, {meta['compiler']}, Release; one run each, wall time", "",
             "| case (labels) | labels 1 thr s | labels s | VTK 1 thr s | VTK s | extract 1 thr s | extract s | "
             "labels / VTK, 1 thr / all (≤ 0.5) | labels / extract, 1 thr / all (≤ 3) | "
             "CPU s labels / VTK / extract, 1 thr | CPU labels / VTK, labels / extract, 1 thr |",
             "|---|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|"]
    for name in cases:
        r = {t: find(name, t) for t in TOOLS}
        count = next((x["labels"] for x in records if x["case"] == name), 0)
        lines.append(f"| {name} ({count}) | " + " | ".join(secs(r[t]) for t in TOOLS) +
                     f" | {ratio(r['labels-1'], r['vtk-1'])} / {ratio(r['labels'], r['vtk'])}"
                     f" | {ratio(r['labels-1'], r['extract-1'])} / {ratio(r['labels'], r['extract'])} | "
                     + " / ".join(f"{r[t]['cpu_seconds']:.2f}" if r[t] else "–"
                                  for t in ("labels-1", "vtk-1", "extract-1"))
                     + f" | {ratio(r['labels-1'], r['vtk-1'], 'cpu_seconds')}, "
                     f"{ratio(r['labels-1'], r['extract-1'], 'cpu_seconds')} |")
    lines += ["", f"labels: `cmc33 labels SEG -o DIR{' --normals' if normals else ''}` (one binary PLY per label "
              f"but 0, {'with' if normals else 'no'} normals); VTK: "
              "vtkNrrdReader -> vtkDiscreteFlyingEdges3D (every label but 0, ComputeNormals) -> vtkPLYWriter "
              "(binary, one file) in python3; extract: `cmc33 extract SEG --iso 0.5 --normals -o out.ply` "
              "(the foreground). 1 thr: `--threads 1`, vtkSMPTools.Initialize(1). CPU s: user + system time of the "
              "process; on a loaded machine it varies less than the wall time."]
    notes = notes + [f"failed: {r['case']}, {r['tool']}: {r['error']}" for r in records if "error" in r]
    if notes:
        lines += ["", "Notes:", ""] + [f"- {n}" for n in notes]
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
