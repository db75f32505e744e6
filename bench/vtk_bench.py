#!/usr/bin/python3
"""Times VTK's vtkFlyingEdges3D on a NRRD volume the way VTK's users run it: through VTK's own
Python wrapping (Debian python3-vtk9), for bench/run_bench.py.

    vtk_bench.py FILE ISO [--threads N] [--repeat R] [--no-normals]

Reads FILE with the reader of skimage_bench.py into a numpy array (outside the timing) and hands
it to a vtkImageData without a copy (numpy_support.numpy_to_vtk, deep=False), in its own type.
Each run builds a new vtkFlyingEdges3D (SetValue(0, ISO), ComputeNormals on unless --no-normals,
ComputeScalars and ComputeGradients off, as cmc33 outputs neither) and times its Update().
--threads N calls vtkSMPTools.Initialize(N) first (0: VTK's default, all cores). Prints one JSON
line: {"tool": "vtk-flying-edges", "seconds": median, "runs_seconds": [...], "vertices": n,
"triangles": n, "threads": n, "smp_backend": "TBB", "vtk_version": "9.1.0", "normals": true}.

Exit codes: 0 measured, 1 the file could not be read or VTK is missing, 2 usage error.
"""

import argparse
import json
import os
import statistics
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from skimage_bench import ArgumentParser, ReadError, read_nrrd  # noqa: E402

PROG = "vtk_bench.py"


def main(argv):
    parser = ArgumentParser(prog=PROG, description="Time vtkFlyingEdges3D (VTK's Python wrapping) on a NRRD volume.")
    parser.add_argument("file", metavar="FILE", help="NRRD volume, header attached (raw or gzip)")
    parser.add_argument("iso", metavar="ISO", type=float, help="isovalue")
    parser.add_argument("--threads", type=int, default=0, metavar="N", help="vtkSMPTools threads, 0 = all cores (default)")
    parser.add_argument("--repeat", type=int, default=5, metavar="R", help="runs; the median is reported (default 5)")
    parser.add_argument("--no-normals", action="store_true", help="ComputeNormals off (default on)")
    args = parser.parse_args(argv)
    if args.repeat < 1:
        parser.error(f"--repeat {args.repeat} is not at least 1")
    if args.threads < 0:
        parser.error(f"--threads {args.threads} is negative")
    try:
        import vtk
        from vtk.util import numpy_support
    except ImportError as e:
        print(f"{PROG}: cannot import {e.name} (Debian: apt-get install python3-vtk9)", file=sys.stderr)
        return 1
    try:
        volume = read_nrrd(args.file)
    except ReadError as e:
        print(f"{PROG}: {e}", file=sys.stderr)
        return 1
    z, y, x = volume.shape
    image = vtk.vtkImageData()
    image.SetDimensions(x, y, z)
    scalars = numpy_support.numpy_to_vtk(volume.reshape(-1), deep=False)
    scalars.SetName("samples")
    image.GetPointData().SetScalars(scalars)
    if args.threads > 0:
        vtk.vtkSMPTools.Initialize(args.threads)
    else:
        vtk.vtkSMPTools.Initialize()

    runs = []
    points = polys = 0
    for _ in range(args.repeat):
        fe = vtk.vtkFlyingEdges3D()
        fe.SetInputData(image)
        fe.SetValue(0, args.iso)
        fe.SetComputeNormals(0 if args.no_normals else 1)
        fe.SetComputeScalars(0)
        fe.SetComputeGradients(0)
        start = time.perf_counter()
        fe.Update()
        runs.append(time.perf_counter() - start)
        out = fe.GetOutput()
        points, polys = out.GetNumberOfPoints(), out.GetNumberOfPolys()
        del fe, out  # free the mesh before the next run allocates one
    print(json.dumps({
        "tool": "vtk-flying-edges", "file": args.file, "iso": args.iso, "dims": [x, y, z],
        "type": str(volume.dtype), "seconds": statistics.median(runs), "runs_seconds": runs,
        "vertices": points, "triangles": polys, "threads": vtk.vtkSMPTools.GetEstimatedNumberOfThreads(),
        "smp_backend": vtk.vtkSMPTools.GetBackend(), "vtk_version": vtk.vtkVersion.GetVTKVersion(),
        "normals": not args.no_normals,
    }))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
