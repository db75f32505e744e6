#!/usr/bin/python3
"""Fig. 12 of Custodio et al. 2013 (C13): the aneurism's vessels per method, the largest
connected component in yellow and every other component in purple, rendered with VTK off screen
(under xvfb-run when there is no display: Debian's VTK renders through X). C13 shows VTK's
vtkMarchingCubes, MC33 and C-MC33; here VTK, mc, mc33-lewiner (MC33) and cmc33, whole and zoomed
on the largest piece that mc33-lewiner cuts off the main vessel.

The isovalue is chosen in the vessels' range (the volume's README: 50-150), among 50, 52, ..., 150,
as the one with the most triangles in pieces that mc33-lewiner cuts off the vessel tree that
cmc33's largest component is (components of mc33-lewiner other than its largest whose vertices
mostly lie on cmc33's largest: a vessel cut off by a misread cell), unless given:
  fig12_render.py [ISO]
Writes docs/figures/fig12_render.{png,svg} (the SVG embeds the rendering) and fig12_render.json.
"""
import os
import shutil
import sys
import tempfile

import numpy as np

import common

METHODS = ["mc", "mc33-lewiner", "cmc33"]
YELLOW, PURPLE = (0.95, 0.80, 0.15), (0.55, 0.30, 0.75)


def on_a_display():
    """Re-runs this script under xvfb-run when there is no X display (VTK needs one here)."""
    if os.environ.get("DISPLAY") or os.environ.get("CMC33_XVFB"):
        return
    if shutil.which("xvfb-run") is None:
        sys.exit("no X display and no xvfb-run: install xvfb (scripts/install-deps.sh --paper)")
    os.environ["CMC33_XVFB"] = "1"
    os.execvp("xvfb-run", ["xvfb-run", "-a", "-s", "-screen 0 1920x1080x24", sys.executable, *sys.argv])


def polydata(positions, triangles):
    import vtk
    from vtk.util import numpy_support
    points = vtk.vtkPoints()
    points.SetData(numpy_support.numpy_to_vtk(positions, deep=1))
    cells = vtk.vtkCellArray()
    ids = np.hstack([np.full((len(triangles), 1), 3, dtype=np.int64), triangles.astype(np.int64)]).ravel()
    cells.SetCells(len(triangles), numpy_support.numpy_to_vtkIdTypeArray(ids, deep=1))
    pd = vtk.vtkPolyData()
    pd.SetPoints(points)
    pd.SetPolys(cells)
    return pd


def vtk_marching_cubes(path, iso):
    import vtk
    image = common.vtk_image(path)
    mc = vtk.vtkMarchingCubes()
    mc.SetInputData(image)
    mc.SetValue(0, iso)
    mc.ComputeNormalsOff()
    mc.Update()
    out = vtk.vtkPolyData()
    out.DeepCopy(mc.GetOutput())
    return out


def components(pd):
    """(point region ids, triangles per region, the largest region) by shared points."""
    import vtk
    from vtk.util import numpy_support
    c = vtk.vtkPolyDataConnectivityFilter()
    c.SetInputData(pd)
    c.SetExtractionModeToAllRegions()
    c.ColorRegionsOn()
    c.Update()
    out = c.GetOutput()
    region = numpy_support.vtk_to_numpy(out.GetPointData().GetArray("RegionId"))
    tris = numpy_support.vtk_to_numpy(out.GetPolys().GetData()).reshape(-1, 4)[:, 1:]
    sizes = np.bincount(region[tris[:, 0]], minlength=c.GetNumberOfExtractedRegions())
    return out, region, sizes, int(np.argmax(sizes))


def keys(points):
    """Positions as integers (1/1024 of a voxel): vertices on one grid edge at one isovalue lie
    at the same crossing whatever the method, so they match."""
    q = np.round(np.asarray(points, dtype=np.float64) * 1024).astype(np.int64)
    return q[:, 0] << 42 | q[:, 1] << 21 | q[:, 2]


def cut_off_pieces(legacy, ours):
    """Components of `legacy` (other than its largest) whose vertices mostly lie on the largest
    component of `ours`: [(triangles, centroid)], largest first."""
    from vtk.util import numpy_support
    out, region, sizes, largest = legacy
    ours_out, ours_region, _, ours_largest = ours
    main = keys(numpy_support.vtk_to_numpy(ours_out.GetPoints().GetData())[ours_region == ours_largest])
    points = numpy_support.vtk_to_numpy(out.GetPoints().GetData())
    on_main = np.isin(keys(points), main)
    pieces = []
    for r in np.nonzero(sizes)[0]:
        if r == largest:
            continue
        mine = region == r
        if on_main[mine].mean() > 0.5:
            pieces.append((int(sizes[r]), points[mine].mean(axis=0)))
    return sorted(pieces, key=lambda x: -x[0])


def choose_iso(path, scratch):
    best = (-1, None)
    for iso in range(50, 151, 2):
        c = {}
        for m in ("mc33-lewiner", "cmc33"):
            (p, t), _ = common.extract(path, iso, m, os.path.join(scratch, "c.ply"))
            c[m] = components(polydata(p, t))
        cut = sum(n for n, _ in cut_off_pieces(c["mc33-lewiner"], c["cmc33"]))
        if cut > best[0]:
            best = (cut, iso)
    return best[1], best[0]


def render(panels, focus, size=520):
    """One row per view (whole, zoom on `focus`), one column per panel; returns an RGB array."""
    import vtk
    from vtk.util import numpy_support
    window = vtk.vtkRenderWindow()
    window.SetOffScreenRendering(1)
    cols, rows = len(panels), 2
    window.SetSize(size * cols, size * rows)
    for col, (name, (pd, region, sizes, largest)) in enumerate(panels):
        main = (region == largest).astype(np.uint8)
        pd.GetPointData().SetScalars(numpy_support.numpy_to_vtk(main, deep=1))
        lut = vtk.vtkLookupTable()
        lut.SetNumberOfTableValues(2)
        lut.SetTableValue(0, *PURPLE, 1.0)
        lut.SetTableValue(1, *YELLOW, 1.0)
        lut.SetRange(0, 1)
        lut.Build()
        for row in range(rows):
            mapper = vtk.vtkPolyDataMapper()
            mapper.SetInputData(pd)
            mapper.SetLookupTable(lut)
            mapper.SetScalarRange(0, 1)
            mapper.SetScalarModeToUsePointData()
            mapper.SetColorModeToMapScalars()  # 0/1 bytes index the table; they are not colours
            actor = vtk.vtkActor()
            actor.SetMapper(mapper)
            actor.GetProperty().SetInterpolationToFlat()
            r = vtk.vtkRenderer()
            r.SetViewport(col / cols, 1 - (row + 1) / rows, (col + 1) / cols, 1 - row / rows)
            r.SetBackground(1, 1, 1)
            r.AddActor(actor)
            camera = r.GetActiveCamera()
            if row == 0:
                camera.SetFocalPoint(128, 128, 128)
                camera.SetPosition(128, -420, 180)
                camera.SetViewUp(0, 0, 1)
                camera.SetViewAngle(30)
                r.ResetCameraClippingRange()
            else:
                # a slab of 60 voxels around the focus: what lies in front of it is clipped away
                camera.SetFocalPoint(*focus)
                camera.SetPosition(focus[0], focus[1] - 90, focus[2] + 40)
                camera.SetViewUp(0, 0, 1)
                camera.SetViewAngle(30)
                distance = camera.GetDistance()
                camera.SetClippingRange(distance - 30, distance + 30)
            window.AddRenderer(r)
    return common.window_rgb(window)


def main():
    on_a_display()
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    path = common.volume("aneurism_256x256x256_uint8.nrrd")
    with tempfile.TemporaryDirectory() as scratch:
        if len(sys.argv) > 1:
            iso, gap = float(sys.argv[1]), None
        else:
            iso, gap = choose_iso(path, scratch)
        panels = [("VTK vtkMarchingCubes", components(vtk_marching_cubes(path, iso)))]
        for m in METHODS:
            (p, t), _ = common.extract(path, iso, m, os.path.join(scratch, m + ".ply"))
            panels.append((m, components(polydata(p, t))))
    # zoom on the largest piece mc33-lewiner cuts off cmc33's main vessel tree
    pieces = cut_off_pieces(panels[2][1], panels[3][1])
    focus = pieces[0][1] if pieces else np.array([128.0, 128.0, 128.0])
    rgb = render(panels, focus)

    fig, ax = plt.subplots(figsize=(13, 6.6))
    ax.imshow(rgb)
    ax.set_axis_off()
    width = rgb.shape[1] / len(panels)
    summary = {"iso": iso, "focus": [float(x) for x in focus], "methods": {},
               "mc33_lewiner_cut_off": [{"triangles": n, "centroid": [float(x) for x in c]} for n, c in pieces]}
    for col, (name, (_, _, sizes, largest)) in enumerate(panels):
        extra = int(sizes.sum() - sizes[largest])
        ax.text((col + 0.5) * width, -12, f"{name}\n{len(sizes)} components\n{extra} of {int(sizes.sum())} triangles "
                "in purple", ha="center", va="bottom", fontsize=8)
        summary["methods"][name] = {"components": int(len(sizes)), "triangles": int(sizes.sum()),
                                    "largest": int(sizes[largest]), "outside_largest": extra}
    fig.suptitle(f"aneurism at iso {iso:g}: largest component yellow, the others purple (C13 Fig. 12); bottom: "
                 "zoom on the largest piece mc33-lewiner cuts off the vessel tree", fontsize=10, y=0.99)
    paths = common.save(fig, "fig12_render")
    json_path = common.write_json("fig12_render", summary)
    print(f"aneurism at iso {iso:g}" + (f" (mc33-lewiner cuts {gap} triangles off the vessel tree of cmc33's "
                                         "largest component, the most among 50..150 by 2)" if gap is not None else ""))
    print(f"  pieces mc33-lewiner cuts off it (triangles): {[n for n, _ in pieces]}")
    for name, s in summary["methods"].items():
        print(f"  {name:>21}: {s['components']} components, {s['outside_largest']} of {s['triangles']} triangles "
              "outside the largest")
    print("wrote " + ", ".join(common.rel(p) for p in [json_path, *paths]))


if __name__ == "__main__":
    main()
