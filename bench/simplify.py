#!/usr/bin/env python3
"""cmc33 simplify beside VTK's vtkQuadricDecimation on the same PLY, one run each, one thread.

Usage: /usr/bin/python3 bench/simplify.py --cmc33 build/cli/cmc33 MESH.ply [--ratio 0.1] [--out DIR]

Each tool simplifies MESH to the ratio of its triangles (one thread; cmc33's time is its own
report of the simplification alone, VTK's the Update() of the filter). Each output is checked by
`cmc33 topo --json` (topology against MESH's, and the exact embedding check). Hausdorff: for
cmc33 the sampled two-sided distance `cmc33 simplify --json` reports (vertices, centroids and a
barycentric grid, exact point-to-triangle distances); for VTK, vtkHausdorffDistancePointSetFilter
(vertices to cells, both ways): not the same sampling, so compare them loosely.
"""

import argparse
import json
import os
import subprocess
import sys
import time


def topo(cmc33, path):
    out = subprocess.run([cmc33, "topo", "--json", path], check=True, capture_output=True, text=True).stdout
    return json.loads(out)


def same_topology(a, b):
    keys = ["euler", "betti", "components", "closed_components", "boundary_loops", "nonmanifold_edges", "nonmanifold_vertices"]
    return all(a[k] == b[k] for k in keys)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("mesh")
    ap.add_argument("--cmc33", required=True)
    ap.add_argument("--ratio", type=float, default=0.1)
    ap.add_argument("--out", default="/tmp/cmc33-bench-simplify")
    args = ap.parse_args()
    os.makedirs(args.out, exist_ok=True)
    before = topo(args.cmc33, args.mesh)
    rows = []

    # cmc33: the library's own timing of the simplification alone (reading, checks and writing excluded)
    ours = os.path.join(args.out, "cmc33.ply")
    t0 = time.perf_counter()
    res = subprocess.run([args.cmc33, "simplify", args.mesh, "-o", ours, "--ratio", str(args.ratio), "--threads", "1",
                          "--json", "--quiet"], check=True, capture_output=True, text=True)
    wall = time.perf_counter() - t0
    j = json.loads(res.stdout)
    rows.append(("cmc33 simplify", j["simplify_seconds"], wall, ours, j["hausdorff"]["distance"]))

    import vtk  # python3-vtk9

    reader = vtk.vtkPLYReader()
    reader.SetFileName(args.mesh)
    reader.Update()
    vtk.vtkMultiThreader.SetGlobalMaximumNumberOfThreads(1)
    dec = vtk.vtkQuadricDecimation()
    dec.SetInputData(reader.GetOutput())
    dec.SetTargetReduction(1 - args.ratio)
    t0 = time.perf_counter()
    dec.Update()
    vtk_seconds = time.perf_counter() - t0
    theirs = os.path.join(args.out, "vtkQuadricDecimation.ply")
    writer = vtk.vtkPLYWriter()
    writer.SetFileName(theirs)
    writer.SetInputData(dec.GetOutput())
    writer.SetFileTypeToBinary()
    writer.Write()
    hd = vtk.vtkHausdorffDistancePointSetFilter()
    hd.SetInputData(0, reader.GetOutput())
    hd.SetInputData(1, dec.GetOutput())
    hd.SetTargetDistanceMethodToPointToCell()
    hd.Update()
    rows.append(("vtkQuadricDecimation", vtk_seconds, vtk_seconds, theirs, hd.GetHausdorffDistance()))

    print(f"{args.mesh}: {before['faces']} triangles, euler {before['euler']}, betti {before['betti']}, ratio {args.ratio}")
    print(f"{'tool':24s} {'seconds':>8s} {'triangles':>10s} {'topology':>9s} {'embedded':>9s} {'Hausdorff':>10s}")
    for name, seconds, _wall, path, hausdorff in rows:
        t = topo(args.cmc33, path)
        emb = t["geometry"]["embedded"] if t.get("geometry") else None
        print(f"{name:24s} {seconds:8.2f} {t['faces']:10d} {'same' if same_topology(before, t) else 'CHANGED':>9s} "
              f"{str(emb):>9s} {hausdorff:10.3f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
