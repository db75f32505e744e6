#!/usr/bin/python3
"""Fig. 8 of Custodio et al. 2013 (C13): a random 5x5x5 field (samples uniform in [-1, 1], as in
the paper) in which two neighbouring cells have tunnels through the face they share. With
Chernyaev's tubes (method chernyaev) both tunnels put a quadrilateral in that face and its sides
become non-manifold edges (red); cmc33-paper splits the slab at the face's saddle (Sec. 6.2) and
cmc33's tubes never touch a face. Only the two cells are drawn: their triangles green (lower) and
yellow (upper), the shared face purple.

The field is the first of `cmc33 verify --method chernyaev --grids 400 --seed 1` whose mesh is
non-manifold. Writes docs/figures/fig8_shared_face.{png,svg,json} and the field as
docs/figures/fig8_field.nrrd.
"""
import csv
import os
import shutil
import subprocess
import sys
import tempfile

import numpy as np

import common
from fig12_render import on_a_display, polydata

METHODS = ["chernyaev", "cmc33-paper", "cmc33"]
GREEN, YELLOW, PURPLE, GREY, RED = (0.3, 0.75, 0.35), (0.95, 0.8, 0.15), (0.55, 0.3, 0.75), (0.8, 0.8, 0.8), (0.85, 0.1, 0.1)


def find_field(scratch):
    """The first random grid of seed 1 where chernyaev's mesh is non-manifold: its NRRD path."""
    failures = os.path.join(scratch, "failures")
    r = subprocess.run([common.CMC33, "verify", "--method", "chernyaev", "--grids", "400", "--seed", "1",
                        "--failures", failures, "--max-failures", "400", "--quiet", "--json"],
                       capture_output=True, text=True)
    if r.returncode not in (0, 1):
        sys.exit(f"cmc33 verify: exit {r.returncode}: {r.stderr.strip()}")
    with open(os.path.join(failures, "failures.tsv")) as f:
        for row in csv.DictReader(f, delimiter="\t"):
            if int(row["nonmanifold_edges"]) > 0:
                return row["file"]
    sys.exit("no non-manifold chernyaev mesh among 400 random grids of seed 1")


def panel(renderer, positions, triangles, cells, edges, face):
    """Adds the triangles in cells[0] (green) and cells[1] (yellow) to `renderer`, with the cells'
    outline, `edges` as red tubes and the shared `face` (axis, plane, (c1, c2)) as a purple square."""
    import vtk
    from vtk.util import numpy_support
    centroid = positions[triangles].mean(axis=1)
    cell = np.floor(centroid).astype(int)
    colour = np.zeros(len(triangles), dtype=np.uint8)
    for k, c in enumerate(cells, start=1):
        colour[np.all(cell == np.asarray(c), axis=1)] = k
    keep = colour > 0  # the two cells' triangles only: the rest would hide them
    triangles, colour = triangles[keep], colour[keep]
    pd = polydata(positions, triangles)
    pd.GetCellData().SetScalars(numpy_support.numpy_to_vtk(colour, deep=1))
    lut = vtk.vtkLookupTable()
    lut.SetNumberOfTableValues(3)
    for k, c in enumerate((GREY, GREEN, YELLOW)):
        lut.SetTableValue(k, *c, 1.0)
    lut.SetRange(0, 2)
    lut.Build()
    mapper = vtk.vtkPolyDataMapper()
    mapper.SetInputData(pd)
    mapper.SetLookupTable(lut)
    mapper.SetScalarRange(0, 2)
    mapper.SetScalarModeToUseCellData()
    mapper.SetColorModeToMapScalars()
    actor = vtk.vtkActor()
    actor.SetMapper(mapper)
    actor.GetProperty().SetInterpolationToFlat()
    actor.GetProperty().EdgeVisibilityOn()
    actor.GetProperty().SetEdgeColor(0.25, 0.25, 0.25)
    actor.GetProperty().SetLineWidth(0.8)
    renderer.AddActor(actor)
    for a, b in edges:
        line = vtk.vtkLineSource()
        line.SetPoint1(*map(float, positions[a]))
        line.SetPoint2(*map(float, positions[b]))
        tube = vtk.vtkTubeFilter()
        tube.SetInputConnection(line.GetOutputPort())
        tube.SetRadius(0.02)
        tube.SetNumberOfSides(12)
        m = vtk.vtkPolyDataMapper()
        m.SetInputConnection(tube.GetOutputPort())
        e = vtk.vtkActor()
        e.SetMapper(m)
        e.GetProperty().SetColor(*RED)
        renderer.AddActor(e)
    box = vtk.vtkOutlineSource()  # the two cells
    lo, hi = np.minimum(cells[0], cells[1]), np.maximum(cells[0], cells[1]) + 1
    box.SetBounds(lo[0], hi[0], lo[1], hi[1], lo[2], hi[2])
    m = vtk.vtkPolyDataMapper()
    m.SetInputConnection(box.GetOutputPort())
    outline = vtk.vtkActor()
    outline.SetMapper(m)
    outline.GetProperty().SetColor(0, 0, 0)
    renderer.AddActor(outline)
    axis, plane, (c1, c2) = face
    others = [a for a in range(3) if a != axis]
    corners = []
    for du, dv in ((0, 0), (1, 0), (1, 1), (0, 1)):
        p = [0.0, 0.0, 0.0]
        p[axis], p[others[0]], p[others[1]] = plane, c1 + du, c2 + dv
        corners.append(p)
    square = vtk.vtkPolyData()
    pts = vtk.vtkPoints()
    for p in corners:
        pts.InsertNextPoint(*p)
    poly = vtk.vtkCellArray()
    poly.InsertNextCell(4, [0, 1, 2, 3])
    square.SetPoints(pts)
    square.SetPolys(poly)
    m = vtk.vtkPolyDataMapper()
    m.SetInputData(square)
    s = vtk.vtkActor()
    s.SetMapper(m)
    s.GetProperty().SetColor(*PURPLE)
    s.GetProperty().SetOpacity(0.55)
    s.GetProperty().LightingOff()  # its colour as it is, seen from either side
    renderer.AddActor(s)


def main():
    on_a_display()
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import vtk

    with tempfile.TemporaryDirectory() as scratch:
        field = find_field(scratch)
        os.makedirs(common.FIGURES, exist_ok=True)
        kept = os.path.join(common.FIGURES, "fig8_field.nrrd")
        shutil.copyfile(field, kept)
        meshes, summaries = {}, {}
        for m in METHODS:
            meshes[m], summaries[m] = common.extract(kept, 0, m, os.path.join(scratch, m + ".ply"), topology=True)
    expected = common.sweep(kept, "0:0:1", ["cmc33"])["rows"][0]["expected"]
    positions, triangles = meshes["chernyaev"]
    edges = common.nonmanifold_edges(triangles)
    faces = sorted(common.shared_faces(positions, edges, np.ones(3)))
    axis, plane, (c1, c2) = faces[0]
    others = [a for a in range(3) if a != axis]
    lower, upper = [0, 0, 0], [0, 0, 0]
    lower[axis], upper[axis] = plane - 1, plane
    lower[others[0]] = upper[others[0]] = c1
    lower[others[1]] = upper[others[1]] = c2

    size = 560
    window = vtk.vtkRenderWindow()
    window.SetOffScreenRendering(1)
    window.SetSize(size * len(METHODS), size)
    centre = np.array(upper, dtype=float) + 0.5
    centre[axis] = plane
    view = np.array([1.3, -1.9, 1.0])
    view[axis] = 0.45  # from a little above the face, mostly beside it
    for col, m in enumerate(METHODS):
        r = vtk.vtkRenderer()
        r.SetViewport(col / len(METHODS), 0, (col + 1) / len(METHODS), 1)
        r.SetBackground(1, 1, 1)
        p, t = meshes[m]
        panel(r, p, t, [lower, upper], common.nonmanifold_edges(t), faces[0])
        camera = r.GetActiveCamera()
        camera.SetFocalPoint(*centre)
        camera.SetPosition(*(centre + 4.2 * view / np.linalg.norm(view)))
        up = [0.0, 0.0, 0.0]
        up[axis] = 1.0  # the two cells one above the other
        camera.SetViewUp(*up)
        camera.SetViewAngle(34)
        r.ResetCameraClippingRange()
        window.AddRenderer(r)
    rgb = common.window_rgb(window)
    w = rgb.shape[1]

    fig, ax = plt.subplots(figsize=(13, 4.9))
    ax.imshow(rgb)
    ax.set_axis_off()
    out = {"field": common.rel(kept), "found_as": os.path.basename(field), "iso": 0, "expected": expected,
           "shared_faces": [{"axis": a, "plane": pl, "cell": list(c)} for a, pl, c in faces], "methods": {}}
    for col, m in enumerate(METHODS):
        t = summaries[m]["topology"]
        g = summaries[m]["geometry"]
        label = (f"{m}: euler {t['euler']}, b0 {t['components']}, b1 {t['betti'][1]}\n"
                 f"{t['nonmanifold_edges']} non-manifold edges"
                 + (f", {summaries[m]['refinement_planes']} plane added" if m == "cmc33-paper" else ""))
        ax.text((col + 0.5) * w / len(METHODS), -10, label, ha="center", va="bottom", fontsize=9)
        out["methods"][m] = {"euler": t["euler"], "b0": t["components"], "b1": t["betti"][1], "b2": t["betti"][2],
                             "nonmanifold_edges": t["nonmanifold_edges"], "embedded": g["embedded"],
                             "refinement_planes": summaries[m].get("refinement_planes")}
    fig.suptitle(f"{os.path.basename(field)} (seed 1), iso 0: two tunnels through one face (C13 Fig. 8); field: "
                 f"euler {expected['euler']}, b0 {expected['b0']}, b1 {expected['b1']}", fontsize=10, y=1.0)
    paths = common.save(fig, "fig8_shared_face")
    json_path = common.write_json("fig8_shared_face", out)
    print(f"{os.path.basename(field)} of seed 1 (5x5x5, uniform in [-1, 1]), iso 0; shared face(s): "
          f"{out['shared_faces']}; the field: euler {expected['euler']}, b0 {expected['b0']}, b1 {expected['b1']}, "
          f"b2 {expected['b2']}")
    for m, s in out["methods"].items():
        right = all(s[k] == expected[k] for k in ("euler", "b0", "b1", "b2"))
        print(f"  {m:>12}: euler {s['euler']}, b0 {s['b0']}, b1 {s['b1']}, b2 {s['b2']}, "
              f"{s['nonmanifold_edges']} non-manifold edges, embedded {s['embedded']}"
              + (f", {s['refinement_planes']} plane added" if m == "cmc33-paper" else "")
              + (" (the field's topology)" if right else " (NOT the field's topology)"))
    print("wrote " + ", ".join(common.rel(p) for p in [json_path, kept, *paths]))


if __name__ == "__main__":
    main()
