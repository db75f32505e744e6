"""What the scripts of scripts/paper share: where things are, running the cmc33 CLI, reading
NRRD volumes and binary PLY meshes into numpy, non-manifold edges, and saving figures.

Run the scripts with Debian's /usr/bin/python3 (python3-matplotlib, python3-numpy, python3-vtk9):
scripts/paper/all.sh installs them and runs everything.
"""
import gzip
import json
import os
import subprocess
import sys

import numpy as np

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
FIGURES = os.path.join(ROOT, "docs", "figures")
VOLUMES = os.environ.get("CMC33_VOLUMES", os.path.join(ROOT, "..", "shared", "data", "volumes"))
CMC33 = os.environ.get("CMC33", os.path.join(ROOT, "build", "cli", "cmc33"))


def volume(name):
    """Path of a volume of ../shared/data/volumes (or $CMC33_VOLUMES); exits naming it if absent."""
    path = os.path.join(VOLUMES, name)
    if not os.path.exists(path):
        sys.exit(f"{path}: not found; the paper's experiments need the volumes of ../shared/data/volumes "
                 "(or set CMC33_VOLUMES to their folder)")
    return path


def cmc33(*args, json_out=False):
    """Runs the cmc33 CLI; returns stdout (parsed if json_out). Exits with its error on failure."""
    if not os.path.exists(CMC33):
        sys.exit(f"{CMC33}: not found; build it (cmake --build build --target cmc33_cli) or set CMC33")
    r = subprocess.run([CMC33, *map(str, args)], capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit(f"cmc33 {' '.join(map(str, args))}: exit {r.returncode}: {r.stderr.strip()}")
    return json.loads(r.stdout) if json_out else r.stdout


def sweep(path, isos, methods, threads=0, expected=True):
    """`cmc33 sweep` as a dict (its JSON). isos: 'FROM:TO:STEP'."""
    args = ["sweep", path, "--iso", isos, "--methods", ",".join(methods), "--json", "--quiet", "--threads", threads]
    if not expected:
        args.append("--no-expected")
    return cmc33(*args, json_out=True)


def rows_by(data, method, key):
    """{iso: row[key]} of one method's rows of a sweep."""
    return {r["iso"]: r[key] for r in data["rows"] if r["method"] == method}


def read_nrrd(path):
    """A NRRD file with an attached header (raw or gzip) as a numpy array [z][y][x], and its
    spacings (x, y, z)."""
    with open(path, "rb") as f:
        data = f.read()
    end = data.index(b"\n\n")
    fields = {}
    for line in data[:end].decode("ascii").splitlines()[1:]:
        if line.startswith("#") or ":" not in line:
            continue
        key, value = line.split(":", 1)
        fields[key.strip()] = value.strip()
    types = {"uint8": "u1", "int8": "i1", "uint16": "u2", "int16": "i2", "uint32": "u4", "int32": "i4",
             "float": "f4", "double": "f8"}
    dtype = np.dtype(types[fields["type"]])
    if dtype.itemsize > 1:
        dtype = dtype.newbyteorder("<" if fields.get("endian", "little") == "little" else ">")
    payload = data[end + 2:]
    if fields.get("encoding") == "gzip":
        payload = gzip.decompress(payload)
    sizes = [int(s) for s in fields["sizes"].split()]
    spacings = [float(s) for s in fields.get("spacings", "1 1 1").split()]
    return np.frombuffer(payload, dtype=dtype).reshape(sizes[::-1]), spacings


def read_ply(path):
    """A binary little-endian PLY as written by `cmc33 extract -o x.ply`: (positions (n, 3) float32,
    triangles (m, 3) uint32)."""
    with open(path, "rb") as f:
        data = f.read()
    end = data.index(b"end_header\n") + len(b"end_header\n")
    header = data[:end].decode("ascii").splitlines()
    vertices = faces = 0
    vertex_props = []
    element = None
    for line in header:
        parts = line.split()
        if parts[:2] == ["element", "vertex"]:
            vertices, element = int(parts[2]), "vertex"
        elif parts[:2] == ["element", "face"]:
            faces, element = int(parts[2]), "face"
        elif parts[:1] == ["property"] and element == "vertex":
            vertex_props.append(parts[1])
    assert all(p == "float" for p in vertex_props), vertex_props
    v = np.frombuffer(data, dtype="<f4", count=vertices * len(vertex_props), offset=end).reshape(vertices, -1)
    f = np.frombuffer(data, dtype=np.dtype([("n", "u1"), ("i", "<u4", 3)]), count=faces,
                      offset=end + v.nbytes)
    assert np.all(f["n"] == 3)
    return np.ascontiguousarray(v[:, :3]), np.ascontiguousarray(f["i"])


def extract(path, iso, method, out, topology=False):
    """`cmc33 extract` to a PLY; returns (positions, triangles) and its --json summary (with the
    mesh's topology and geometry if `topology`)."""
    args = ["extract", path, "--iso", iso, "--method", method, "-o", out, "--json", "--quiet"]
    summary = cmc33(*args, *([] if topology else ["--no-topology"]), json_out=True)
    return read_ply(out), summary


def nonmanifold_edges(triangles):
    """Edges (sorted vertex pairs, (k, 2)) used by more than two triangles."""
    e = np.concatenate([triangles[:, [0, 1]], triangles[:, [1, 2]], triangles[:, [2, 0]]])
    e.sort(axis=1)
    pairs, counts = np.unique(e, axis=0, return_counts=True)
    return pairs[counts > 2]


def shared_faces(positions, edges, spacing):
    """The grid faces that non-manifold edges of a legacy mesh lie in: Chernyaev's tube lies in
    the face where two tunnels meet (C13 Sec. 5.2), so both ends of such an edge have one
    coordinate on a sample plane and the edge lies in one grid face. Returns a set of
    (axis, plane, cell of the other two axes): one per case."""
    faces = set()
    for a, b in edges:
        pa, pb = positions[a] / spacing, positions[b] / spacing
        for axis in range(3):
            if abs(pa[axis] - round(pa[axis])) < 1e-4 and abs(pb[axis] - round(pb[axis])) < 1e-4 \
                    and round(pa[axis]) == round(pb[axis]):
                mid = (pa + pb) / 2
                others = tuple(int(np.floor(mid[c])) for c in range(3) if c != axis)
                faces.add((axis, int(round(pa[axis])), others))
                break
    return faces


def vtk_image(path):
    """The NRRD volume at `path` as a vtkImageData (samples copied, spacing kept)."""
    import vtk
    from vtk.util import numpy_support
    v, spacing = read_nrrd(path)
    image = vtk.vtkImageData()
    image.SetDimensions(v.shape[2], v.shape[1], v.shape[0])
    image.SetSpacing(*spacing)
    image.GetPointData().SetScalars(numpy_support.numpy_to_vtk(np.ascontiguousarray(v).ravel(), deep=1))
    return image


def window_rgb(window):
    """Renders a VTK render window off screen and returns its pixels as an (h, w, 3) uint8 array,
    top row first."""
    import vtk
    from vtk.util import numpy_support
    window.Render()
    grab = vtk.vtkWindowToImageFilter()
    grab.SetInput(window)
    grab.ReadFrontBufferOff()
    grab.Update()
    image = grab.GetOutput()
    w, h, _ = image.GetDimensions()
    return numpy_support.vtk_to_numpy(image.GetPointData().GetScalars()).reshape(h, w, -1)[::-1, :, :3]


def save(fig, name):
    """Writes docs/figures/NAME.svg and .png; returns their paths. No date and fixed ids in the
    SVG, so the same data give the same files."""
    import matplotlib
    matplotlib.rcParams["svg.hashsalt"] = "cmc33"
    os.makedirs(FIGURES, exist_ok=True)
    paths = [os.path.join(FIGURES, name + ext) for ext in (".svg", ".png")]
    fig.savefig(paths[0], bbox_inches="tight", metadata={"Date": None})
    fig.savefig(paths[1], bbox_inches="tight", dpi=130)
    return paths


def write_json(name, data):
    """docs/figures/NAME.json, compact (one object)."""
    os.makedirs(FIGURES, exist_ok=True)
    path = os.path.join(FIGURES, name + ".json")
    with open(path, "w") as f:
        json.dump(data, f, separators=(",", ":"))
        f.write("\n")
    return path


def rel(path):
    return os.path.relpath(path, ROOT)
