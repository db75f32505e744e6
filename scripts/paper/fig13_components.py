#!/usr/bin/python3
"""Fig. 13 of Custodio et al. 2013 on the aneurism volume: the difference in connected components
between classic Marching Cubes and cmc33, and between MC33 (mc33-lewiner) and cmc33, over every
integer isovalue the data covers (1..254: at 0 every sample is above, at 255 only the saturated
ones); VTK's vtkMarchingCubes as a third curve (the paper compared with VTK), and chernyaev too.

Writes docs/figures/fig13_components.{json,svg,png}; the JSON is `cmc33 sweep`'s, with a "vtk"
key: {"iso": [...], "b0": [...], "triangles": [...]} (or null without python3-vtk9).
"""
import sys

import common

ISOS = "1:254:1"
METHODS = ["cmc33", "chernyaev", "mc33-lewiner", "mc"]


def vtk_components(path, isos):
    """Components of vtkMarchingCubes' mesh (points merged, as VTK merges them) per isovalue."""
    try:
        import vtk
    except ImportError:
        print("python3-vtk9 is missing: no VTK curve (scripts/install-deps.sh --paper installs it)")
        return None
    image = common.vtk_image(path)
    mc = vtk.vtkMarchingCubes()
    mc.SetInputData(image)
    mc.ComputeNormalsOff()
    mc.ComputeGradientsOff()
    mc.ComputeScalarsOff()
    connectivity = vtk.vtkPolyDataConnectivityFilter()
    connectivity.SetInputConnection(mc.GetOutputPort())
    connectivity.SetExtractionModeToAllRegions()
    out = {"version": vtk.vtkVersion.GetVTKVersion(), "iso": [], "b0": [], "triangles": []}
    for iso in isos:
        mc.SetValue(0, iso)
        connectivity.Update()
        out["iso"].append(iso)
        out["b0"].append(connectivity.GetNumberOfExtractedRegions())
        out["triangles"].append(mc.GetOutput().GetNumberOfPolys())
    return out


def main():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    path = common.volume("aneurism_256x256x256_uint8.nrrd")
    data = common.sweep(path, ISOS, METHODS)
    isos = sorted(common.rows_by(data, "cmc33", "b0"))
    b0 = {m: common.rows_by(data, m, "b0") for m in METHODS}
    vtk_curve = vtk_components(path, isos)
    data["vtk"] = vtk_curve
    bad = [i for i, r in common.rows_by(data, "cmc33", "expected").items()
           if r is None or any(r[k] != common.rows_by(data, "cmc33", k)[i] for k in ("euler", "b0", "b1", "b2"))]

    fig, axes = plt.subplots(1, 2, figsize=(11, 3.8), sharey=False)
    diff = {m: [b0[m][i] - b0["cmc33"][i] for i in isos] for m in METHODS}
    if vtk_curve:
        vtk_diff = [b - b0["cmc33"][i] for i, b in zip(vtk_curve["iso"], vtk_curve["b0"])]
        axes[0].plot(vtk_curve["iso"], vtk_diff, color="tab:purple", lw=1.2, label="VTK vtkMarchingCubes - cmc33")
    axes[0].plot(isos, diff["mc"], color="tab:blue", lw=1.2, label="mc - cmc33")
    axes[0].set_title("classic Marching Cubes against cmc33")
    axes[1].plot(isos, diff["mc33-lewiner"], color="tab:red", lw=1.2, label="mc33-lewiner - cmc33")
    axes[1].plot(isos, diff["chernyaev"], color="tab:green", lw=1.0, ls="--", label="chernyaev - cmc33")
    axes[1].set_title("MC33 against cmc33")
    for ax in axes:
        ax.axhline(0, color="0.5", lw=0.6)
        ax.set_xlabel("isovalue")
        ax.set_ylabel("difference in connected components")
        ax.legend(frameon=False, fontsize=8)
        ax.grid(alpha=0.25)
    fig.suptitle("aneurism 256^3 uint8: components of each method minus those of cmc33 (C13 Fig. 13)", fontsize=10)
    paths = common.save(fig, "fig13_components")
    json_path = common.write_json("fig13_components", data)

    print(f"aneurism, isovalues {ISOS} ({len(isos)}), methods {', '.join(METHODS)}"
          + (f", and VTK {vtk_curve['version']} vtkMarchingCubes" if vtk_curve else ""))
    print(f"cmc33 equals the field's topology at {len(isos) - len(bad)} of {len(isos)} isovalues"
          + (f"; differs at {bad}" if bad else ""))
    curves = [("mc", diff["mc"]), ("mc33-lewiner", diff["mc33-lewiner"]), ("chernyaev", diff["chernyaev"])]
    if vtk_curve:
        curves.insert(0, ("VTK", vtk_diff))
    for name, d in curves:
        more = sum(x > 0 for x in d)
        fewer = sum(x < 0 for x in d)
        top = max(range(len(d)), key=lambda k: d[k])
        print(f"  {name:>12} - cmc33: max {max(d):+d} components (iso {isos[top]}), min {min(d):+d}; "
              f"more at {more} isovalues, fewer at {fewer}, equal at {len(d) - more - fewer}")
    print("wrote " + ", ".join(common.rel(p) for p in [json_path, *paths]))
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
