#!/usr/bin/env python3
"""Figures for the "Geometry" section of docs/conventions.md.

They show, on meshes that the cmc33 CLI extracts, how cmc33 keeps its meshes
embedded in space:

* tie_disc  -- a 3x3x3 volume whose middle layer of samples is exactly at the
  isovalue (one sample of it is lowered). A sample equal to iso counts as
  above, and a vertex that would land on a sample is moved 2^-10 of an edge
  along its edge, so the disc passes just below the tied samples; the zoom
  shows the vertices around one tied sample.
* tie_bump  -- a one-voxel bump exactly at the isovalue: 3x3x3 of 60 with the
  centre 80, iso 80. The mesh is a closed octahedron with its 6 vertices at
  2^-10 from the centre sample, not a single point.
* tube_cell -- single cells whose interior test joins the two sides (subcases
  4.1.2, 6.1.2, 7.4.2): the tube between the loops on the cell's faces and the
  extra interior vertices it uses.

Each figure is written as PNG and SVG next to this script. Regenerate all of
them from the repository root with:

    python3 docs/figures/geometry_figures.py build/cli/cmc33

(any python3 with numpy and matplotlib; on Debian: apt-get install
python3-matplotlib python3-numpy, then /usr/bin/python3).
"""
import json
import subprocess
import sys
import tempfile
from pathlib import Path

import matplotlib
matplotlib.use("Agg")
matplotlib.rcParams["svg.hashsalt"] = "cmc33"   # stable ids in the SVGs
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib import colors, ticker  # noqa: E402
from mpl_toolkits.mplot3d.art3d import Poly3DCollection  # noqa: E402

HERE = Path(__file__).resolve().parent
DELTA = 2.0 ** -10           # the offset of a vertex that would sit on a sample
DPI = 110
FACE, EDGE = "#7fb3d5", "#1f4e79"
TIED, ABOVE, BELOW = "#d62728", "#ff7f0e", "#7f7f7f"

# Corner values (order (0,0,0) (1,0,0) (0,1,0) (1,1,0) (0,0,1) (1,0,1) (0,1,1)
# (1,1,1), iso 0). 4.1.2 is by hand; the other two are the first cells of the
# right subcase among random values in [-1, 1] (numpy default_rng(1)).
TUBE_CELLS = {
    "4.1.2": [1.0, -0.25, -0.25, -0.25, -0.25, -0.25, -0.25, 1.0],
    "6.1.2": [-0.18, 0.5, -0.95, 0.87, 0.43, -0.98, 0.42, 0.16],
    "7.4.2": [-0.63, 0.78, 0.69, -0.73, -0.09, -0.38, -0.31, 0.53],
}


def write_nrrd(path, vol):
    """vol is indexed [z, y, x], so its bytes are x fastest."""
    nz, ny, nx = vol.shape
    head = (f"NRRD0004\ntype: uint8\ndimension: 3\nsizes: {nx} {ny} {nz}\n"
            "encoding: raw\nendian: little\n\n")
    Path(path).write_bytes(head.encode() + vol.astype(np.uint8).tobytes())


def read_obj(path):
    verts, faces = [], []
    for line in Path(path).read_text().splitlines():
        tok = line.split()
        if tok and tok[0] == "v":
            verts.append([float(t) for t in tok[1:4]])
        elif tok and tok[0] == "f":
            faces.append([int(t.split("/")[0]) - 1 for t in tok[1:4]])
    return np.array(verts), np.array(faces, dtype=int)


def extract(cmc33, vol, iso, tmp, name):
    src, obj = Path(tmp) / f"{name}.nrrd", Path(tmp) / f"{name}.obj"
    write_nrrd(src, vol)
    subprocess.run([cmc33, "extract", str(src), "--iso", str(iso), "-o", str(obj)],
                   check=True, capture_output=True)
    return read_obj(obj)


def clip(poly, lo, hi):
    """Sutherland-Hodgman: the part of a convex polygon inside the box [lo, hi]."""
    for axis in range(3):
        for bound, sign in ((lo[axis], 1), (hi[axis], -1)):
            out = []
            for a, b in zip(poly, poly[1:] + poly[:1]):
                da, db = sign * (a[axis] - bound), sign * (b[axis] - bound)
                if da >= 0:
                    out.append(a)
                if da * db < 0:
                    out.append(a + (b - a) * (da / (da - db)))
            poly = out
            if not poly:
                return []
    return poly


def draw_mesh(ax, polys, alpha=0.55):
    """Triangles (or clipped polygons), shaded by the angle to a fixed light."""
    light = np.array([0.3, -0.5, 0.8]) / np.linalg.norm([0.3, -0.5, 0.8])
    base = np.array(colors.to_rgb(FACE))
    colours = []
    for p in polys:
        n = np.cross(p[1] - p[0], p[2] - p[0])
        n = n / (np.linalg.norm(n) or 1.0)
        colours.append((*(base * (0.55 + 0.45 * abs(n @ light))), alpha))
    ax.add_collection3d(Poly3DCollection(polys, facecolors=colours, edgecolor=EDGE,
                                         linewidth=0.8))


def box_axes(ax, lo, hi, labels=("x", "y", "z")):
    ax.set_xlim(lo[0], hi[0]); ax.set_ylim(lo[1], hi[1]); ax.set_zlim(lo[2], hi[2])
    ax.set_xlabel(labels[0]); ax.set_ylabel(labels[1]); ax.set_zlabel(labels[2])
    ax.set_box_aspect((1, 1, 1))
    ax.tick_params(labelsize=7, pad=0)
    for axis in (ax.xaxis, ax.yaxis, ax.zaxis):
        axis.set_major_locator(ticker.MaxNLocator(4))
        axis.labelpad = -2


def zoom(ax, V, F, sample, half, title):
    """Mesh near `sample`, in units of 1e-3 of an edge, offsets from the sample."""
    lo, hi = sample - half, sample + half
    polys = [clip([V[i] for i in f], lo, hi) for f in F]
    draw_mesh(ax, [(np.array(p) - sample) * 1e3 for p in polys if len(p) >= 3])
    near = V[np.linalg.norm(V - sample, axis=1) < half]
    for v in near:
        d = (v - sample) * 1e3
        ax.plot(*zip((0, 0, 0), d), color=TIED, linestyle="--", linewidth=1)
        ax.scatter(*d, color=EDGE, s=18, depthshade=False)
    ax.scatter(0, 0, 0, color=TIED, s=50, depthshade=False)
    h = half * 1e3
    box_axes(ax, (-h,) * 3, (h,) * 3, ("Δx (10⁻³)", "Δy (10⁻³)", "Δz (10⁻³)"))
    ax.set_title(f"{title}\nδ = 2⁻¹⁰ ≈ {DELTA * 1e3:.3f}·10⁻³ of an edge", fontsize=10)
    ax.text2D(0.5, -0.04, "red: the sample; dashed: sample → vertex, length δ",
              transform=ax.transAxes, fontsize=8.5, ha="center")


def save(fig, name):
    fig.savefig(HERE / f"{name}.png", dpi=DPI)
    fig.savefig(HERE / f"{name}.svg", metadata={"Date": None})  # byte-reproducible
    plt.close(fig)
    print("wrote", HERE / f"{name}.png", "and .svg")


def samples(ax, vol, iso):
    z, y, x = np.indices(vol.shape)
    for mask, colour, label in ((vol > iso, ABOVE, "above iso"), (vol == iso, TIED, "= iso"),
                                (vol < iso, BELOW, "below iso")):
        if mask.any():
            ax.scatter(x[mask], y[mask], z[mask], color=colour, s=22, label=label,
                       depthshade=False)


def tie_disc(cmc33, tmp):
    vol = np.empty((3, 3, 3), dtype=np.uint8)
    vol[0], vol[1], vol[2] = 60, 80, 100     # layer z = 1 exactly at iso 80
    vol[1, 0, 1] = 70                         # ... except sample (1, 0, 1)
    V, F = extract(cmc33, vol, 80, tmp, "disc")
    fig = plt.figure(figsize=(8.2, 4.3))
    ax = fig.add_subplot(1, 2, 1, projection="3d")
    draw_mesh(ax, [V[f] for f in F], alpha=0.45)
    samples(ax, vol, 80)
    ax.scatter(*V.T, color=EDGE, s=10, depthshade=False)
    box_axes(ax, (0, 0, 0), (2, 2, 2))
    ax.view_init(elev=18, azim=-60)
    ax.legend(loc="upper left", fontsize=8)
    ax.set_title(f"layer z = 1 at iso 80, sample (1,0,1) = 70\n"
                 f"{len(V)} vertices, {len(F)} triangles", fontsize=10)
    zoom(fig.add_subplot(1, 2, 2, projection="3d", computed_zorder=False),
         V, F, np.array([1.0, 1.0, 1.0]),
         2.5e-3, "zoom on the tied sample (1,1,1)")
    fig.axes[1].view_init(elev=12, azim=15)
    fig.subplots_adjust(left=0.02, right=0.96, bottom=0.08, top=0.86, wspace=0.15)
    save(fig, "tie_disc")


def tie_bump(cmc33, tmp):
    vol = np.full((3, 3, 3), 60, dtype=np.uint8)
    vol[1, 1, 1] = 80
    V, F = extract(cmc33, vol, 80, tmp, "bump")
    fig = plt.figure(figsize=(8.2, 4.3))
    ax = fig.add_subplot(1, 2, 1, projection="3d")
    samples(ax, vol, 80)
    draw_mesh(ax, [V[f] for f in F])
    box_axes(ax, (0, 0, 0), (2, 2, 2))
    ax.view_init(elev=18, azim=-60)
    ax.legend(loc="upper left", fontsize=8)
    ax.text2D(0.98, 0.93, "the mesh is at the red sample,\ntoo small to see here",
              transform=ax.transAxes, fontsize=8.5, ha="right")
    ax.set_title(f"3×3×3 of 60, centre 80, iso 80\n{len(V)} vertices, {len(F)} triangles",
                 fontsize=10)
    zoom(fig.add_subplot(1, 2, 2, projection="3d", computed_zorder=False),
         V, F, np.array([1.0, 1.0, 1.0]),
         1.5e-3, "zoom: a closed octahedron around the sample")
    fig.axes[1].view_init(elev=20, azim=-35)
    fig.subplots_adjust(left=0.02, right=0.96, bottom=0.08, top=0.86, wspace=0.15)
    save(fig, "tie_bump")


CUBE_EDGES = [(a, b) for a in range(8) for b in range(8)
              if a < b and bin(a ^ b).count("1") == 1]
CORNERS = np.array([[c & 1, (c >> 1) & 1, (c >> 2) & 1] for c in range(8)], dtype=float)


def tube_cell(cmc33):
    fig = plt.figure(figsize=(8.2, 3.5))
    for k, (want, values) in enumerate(TUBE_CELLS.items()):
        out = subprocess.run([cmc33, "cell", "--json", "--", *map(str, values)],
                             check=True, capture_output=True, text=True).stdout
        cell = json.loads(out)
        assert cell["subcase"] == want, (want, cell["subcase"])
        V = np.array(cell["mesh"]["vertices"])
        F = np.array(cell["mesh"]["triangles"])
        ax = fig.add_subplot(1, 3, k + 1, projection="3d")
        for a, b in CUBE_EDGES:
            ax.plot(*zip(CORNERS[a], CORNERS[b]), color="black", linewidth=0.7)
        up = np.array(values) >= cell["iso"]
        ax.scatter(*CORNERS[up].T, color=ABOVE, s=30, depthshade=False, label="corner above")
        ax.scatter(*CORNERS[~up].T, color=BELOW, s=12, depthshade=False, label="corner below")
        draw_mesh(ax, [V[f] for f in F], alpha=0.35)
        # A vertex on a cube edge has two coordinates that are 0 or 1.
        on_edge = np.sum(np.isclose(V, 0) | np.isclose(V, 1), axis=1) >= 2
        ax.scatter(*V[on_edge].T, color="#2ca02c", s=18, depthshade=False, label="loop vertex")
        ax.scatter(*V[~on_edge].T, color="#9467bd", s=18, depthshade=False,
                   label="interior vertex")
        box_axes(ax, (0, 0, 0), (1, 1, 1))
        ax.set_axis_off()
        # Look down the tube: along the diagonal between the two corners that the
        # interior test joined, turned a little so that its wall shows.
        d = CORNERS[cell["interior"]["corner_c"]] - CORNERS[cell["interior"]["corner_a"]]
        d = d if d[2] >= 0 else -d
        ax.view_init(elev=np.degrees(np.arcsin(d[2] / np.linalg.norm(d))) - 10,
                     azim=np.degrees(np.arctan2(d[1], d[0])) + 15)
        ax.set_title(f"subcase {cell['subcase']}: {len(F)} triangles", fontsize=10)
    fig.legend(*fig.axes[0].get_legend_handles_labels(), loc="lower center", ncol=4,
               fontsize=8)
    fig.subplots_adjust(left=0.01, right=0.97, bottom=0.1, top=0.9, wspace=0.08)
    save(fig, "tube_cell")


def main():
    root = HERE.parent.parent
    cmc33 = Path(sys.argv[1]) if len(sys.argv) > 1 else root / "build" / "cli" / "cmc33"
    cmc33 = str(cmc33.resolve())
    with tempfile.TemporaryDirectory() as tmp:
        tie_disc(cmc33, tmp)
        tie_bump(cmc33, tmp)
    tube_cell(cmc33)


if __name__ == "__main__":
    main()
