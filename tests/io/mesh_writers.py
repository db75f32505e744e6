#!/usr/bin/python3
"""cmc33's glTF, VTK XML PolyData and GIfTI files read by independent readers, each compared with
the PLY `cmc33 extract` writes of the same volume (vertices, normals and triangles, exactly):

  glb        VTK's vtkGLTFReader on .glb and .gltf (+ .bin)
  validator  the Khronos glTF validator (tests/io/gltf, npm ci): 0 errors, 0 warnings
  vtp        VTK's vtkXMLPolyDataReader (points, Normals, polys), no VTK error or warning
  gii        nibabel.load with warnings as errors: pointset, triangles, normals; a mesh in LPS+
             (--space lps) comes back in RAS+, and a mirrored space (left-anterior-superior)
             with x negated and each triangle's winding reversed

Usage: mesh_writers.py --cmc33 PATH --work DIR --only glb|validator|vtp|gii
Exit 77 (CTest: skipped) only when the independent reader itself is missing (python3-vtk9,
python3-nibabel, node and npm); a reader that is there and disagrees fails.
"""

import argparse
import json
import os
import shutil
import subprocess
import sys
import warnings

SKIP = 77
HERE = os.path.dirname(os.path.abspath(__file__))
try:
    import numpy as np
except ImportError:
    print("skipped: numpy is not installed (python3-numpy)")
    sys.exit(SKIP)


def run(cmd):
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0:
        raise AssertionError(f"{' '.join(cmd)} failed ({r.returncode}): {r.stderr.strip()} {r.stdout.strip()}")
    return r


def read_ascii_ply(path):
    """(positions (n, 3) float32, normals (n, 3) float32 or None, triangles (m, 3) int64)."""
    with open(path, "rb") as f:
        header, body = f.read().split(b"end_header\n", 1)
    nv = nf = 0
    props = 0
    for line in header.decode().splitlines():
        w = line.split()
        if w[:2] == ["element", "vertex"]:
            nv = int(w[2])
        elif w[:2] == ["element", "face"]:
            nf = int(w[2])
        elif w[:1] == ["property"] and nf == 0 and w[1] != "list":
            props += 1
    lines = body.decode().splitlines()
    v = np.array([[np.float32(x) for x in lines[i].split()] for i in range(nv)], dtype=np.float32).reshape(nv, props)
    f = np.array([[int(x) for x in lines[nv + i].split()[1:]] for i in range(nf)], dtype=np.int64).reshape(nf, 3)
    return v[:, :3], (v[:, 3:6] if props >= 6 else None), f


def write_volume(path):
    """A NIfTI (RAS+) of a smooth closed surface, with a frame that is not the identity."""
    import nibabel as nib
    grids = np.meshgrid(*[np.linspace(-1, 1, n) for n in (14, 12, 10)], indexing="ij")
    r = np.sqrt((grids[0] * 1.0) ** 2 + (grids[1] * 1.2) ** 2 + (grids[2] * 0.9) ** 2)
    samples = (1.0 - r).astype(np.float32)
    affine = np.diag([0.8, 1.1, 1.5, 1.0])
    affine[:3, 3] = [-12.5, 30.25, 4.0]
    nib.save(nib.Nifti1Image(samples, affine), path)


def write_las_nrrd(path):
    """The same kind of field in a NRRD whose space is left-anterior-superior (one axis mirrored from RAS)."""
    grids = np.meshgrid(*[np.linspace(-1, 1, n) for n in (9, 10, 11)], indexing="ij")
    a = (1.0 - np.sqrt(grids[0] ** 2 + (1.1 * grids[1]) ** 2 + (0.9 * grids[2]) ** 2)).astype("<f4")
    header = ("NRRD0004\ntype: float\ndimension: 3\nspace: left-anterior-superior\nsizes: 9 10 11\n"
              "space directions: (1,0,0) (0,1.5,0) (0,0,2)\nspace origin: (3,-4,5)\nendian: little\n"
              "encoding: raw\n\n")
    with open(path, "wb") as f:
        f.write(header.encode())
        f.write(a.tobytes(order="F"))


class Case:
    def __init__(self, cmc33, work):
        self.cmc33, self.work = cmc33, work
        self.volume = os.path.join(work, "volume.nii")
        write_volume(self.volume)

    def path(self, name):
        return os.path.join(self.work, name)

    def extract(self, out, *extra, volume=None, normals=True):
        run([self.cmc33, "extract", volume or self.volume, "--iso", "0.25", *(["--normals"] if normals else []),
             "-o", self.path(out), "--quiet", *extra])
        return self.path(out)

    def reference(self, *extra, volume=None, name="ref.ply"):
        run([self.cmc33, "extract", volume or self.volume, "--iso", "0.25", "--normals", "--ascii", "-o",
             self.path(name), "--quiet", *extra])
        p, n, t = read_ascii_ply(self.path(name))
        if len(t) == 0:
            raise AssertionError("the reference mesh is empty")
        return p, n, t


def same(what, got, want):
    got, want = np.asarray(got), np.asarray(want)
    if got.shape != want.shape:
        raise AssertionError(f"{what}: shape {got.shape}, expected {want.shape}")
    if not np.array_equal(got, want):
        bad = np.argwhere(got != want)[0]
        raise AssertionError(f"{what}: differs first at {tuple(bad)}: {got[tuple(bad)]} != {want[tuple(bad)]}")


# ---- VTK ------------------------------------------------------------------------------------

def vtk_or_skip():
    try:
        import vtk  # noqa: F401
        from vtk.util.numpy_support import vtk_to_numpy  # noqa: F401
    except ImportError:
        print("skipped: VTK's Python module is not installed (python3-vtk9)")
        sys.exit(SKIP)
    import vtk
    return vtk


class VtkMessages:
    """Collects every error and warning VTK reports while reading (none may appear)."""
    def __init__(self, vtk):
        self.messages = []
        self.window = vtk.vtkStringOutputWindow()
        vtk.vtkOutputWindow.SetInstance(self.window)

    def check(self, what):
        text = self.window.GetOutput().strip()
        if text:
            raise AssertionError(f"{what}: VTK reported: {text}")


def triangles_of(vtk, poly):
    from vtk.util.numpy_support import vtk_to_numpy
    polys = poly.GetPolys()
    offsets = vtk_to_numpy(polys.GetOffsetsArray())
    conn = vtk_to_numpy(polys.GetConnectivityArray())
    if not np.all(np.diff(offsets) == 3):
        raise AssertionError("a polygon that is not a triangle")
    return conn.reshape(-1, 3).astype(np.int64)


def check_vtp(case):
    vtk = vtk_or_skip()
    from vtk.util.numpy_support import vtk_to_numpy
    p, n, t = case.reference()
    path = case.extract("m.vtp")
    messages = VtkMessages(vtk)
    reader = vtk.vtkXMLPolyDataReader()
    reader.SetFileName(path)
    reader.Update()
    messages.check(path)
    poly = reader.GetOutput()
    if poly.GetNumberOfPoints() != len(p) or poly.GetNumberOfPolys() != len(t):
        raise AssertionError(f"{path}: {poly.GetNumberOfPoints()} points and {poly.GetNumberOfPolys()} polys, "
                             f"expected {len(p)} and {len(t)}")
    same(f"{path} points", vtk_to_numpy(poly.GetPoints().GetData()), p)
    same(f"{path} triangles", triangles_of(vtk, poly), t)
    normals = poly.GetPointData().GetNormals()
    if normals is None or normals.GetName() != "Normals":
        raise AssertionError(f"{path}: no Normals attribute")
    same(f"{path} normals", vtk_to_numpy(normals), n)
    # an empty mesh (iso above every sample) reads as 0 points and 0 polys
    empty = case.path("empty.vtp")
    run([case.cmc33, "extract", case.volume, "--iso", "5", "-o", empty, "--quiet"])
    reader = vtk.vtkXMLPolyDataReader()
    reader.SetFileName(empty)
    reader.Update()
    messages.check(empty)
    if reader.GetOutput().GetNumberOfPoints() != 0 or reader.GetOutput().GetNumberOfPolys() != 0:
        raise AssertionError(f"{empty}: not empty")
    return 2


def check_glb(case):
    vtk = vtk_or_skip()
    from vtk.util.numpy_support import vtk_to_numpy
    if not hasattr(vtk, "vtkGLTFReader"):
        print("skipped: this VTK has no vtkGLTFReader")
        sys.exit(SKIP)
    p, n, t = case.reference()
    count = 0
    for name in ("m.glb", "m.gltf"):
        path = case.extract(name)
        messages = VtkMessages(vtk)
        reader = vtk.vtkGLTFReader()
        reader.SetFileName(path)
        reader.Update()
        messages.check(path)
        blocks = reader.GetOutput()
        it = blocks.NewIterator()
        it.InitTraversal()
        polys = []
        while not it.IsDoneWithTraversal():
            polys.append(it.GetCurrentDataObject())
            it.GoToNextItem()
        if len(polys) != 1:
            raise AssertionError(f"{path}: {len(polys)} meshes, expected 1")
        poly = polys[0]
        if poly.GetNumberOfPoints() != len(p) or poly.GetNumberOfPolys() != len(t):
            raise AssertionError(f"{path}: {poly.GetNumberOfPoints()} points and {poly.GetNumberOfPolys()} "
                                 f"triangles, expected {len(p)} and {len(t)}")
        same(f"{path} points", vtk_to_numpy(poly.GetPoints().GetData()), p)
        same(f"{path} triangles", triangles_of(vtk, poly), t)
        normals = poly.GetPointData().GetNormals() or poly.GetPointData().GetArray("NORMAL")
        if normals is None:
            raise AssertionError(f"{path}: no normals")
        # vtkGLTFReader normalises the normals it reads again (a last-bit difference); the bytes
        # themselves are checked by test_mesh_write_formats.cpp
        got = vtk_to_numpy(normals)
        if got.shape != n.shape or np.abs(got - n).max() > 1e-6:
            raise AssertionError(f"{path}: normals differ from the PLY's by more than 1e-6")
        count += 1
    return count


def check_validator(case):
    node, npm = shutil.which("node"), shutil.which("npm")
    if not node or not npm:
        print("skipped: node and npm are needed for the Khronos glTF validator (scripts/install-deps.sh --web)")
        sys.exit(SKIP)
    folder = os.path.join(HERE, "gltf")
    if not os.path.isdir(os.path.join(folder, "node_modules", "gltf-validator")):
        run([os.path.join(folder, "install.sh")])
    files = [case.extract("v.glb"), case.extract("v.gltf"), case.extract("plain.glb", normals=False),
             case.extract("far.glb", "--positions", "double")]
    empty = case.path("empty.glb")
    run([case.cmc33, "extract", case.volume, "--iso", "5", "-o", empty, "--quiet"])
    files.append(empty)
    scenes, labels = label_scenes(case)
    files += scenes
    r = subprocess.run([node, os.path.join(folder, "validate.mjs"), *files], capture_output=True, text=True)
    reports = [json.loads(line) for line in r.stdout.splitlines() if line.startswith("{")]
    if r.returncode != 0 or len(reports) != len(files):
        raise AssertionError(f"the glTF validator: exit {r.returncode}: {r.stdout.strip()} {r.stderr.strip()}")
    for rep in reports:
        if rep["errors"] or rep["warnings"]:
            raise AssertionError(f"{rep['uri']}: {rep['errors']} errors, {rep['warnings']} warnings: {rep['messages']}")
    # the validator counted what the file holds
    info = reports[0]["info"]
    _, _, t = case.reference()
    if info.get("totalTriangleCount") != len(t):
        raise AssertionError(f"{files[0]}: the validator counts {info.get('totalTriangleCount')} triangles, "
                             f"expected {len(t)}")
    # a label map's scene: one named, coloured mesh per label, as many triangles as the surfaces
    for path, rep in zip(scenes, reports[-len(scenes):]):
        want = sum(label["triangles"] for label in labels)
        if rep["info"].get("totalTriangleCount") != want:
            raise AssertionError(f"{path}: the validator counts {rep['info'].get('totalTriangleCount')} triangles, "
                                 f"expected the label surfaces' {want}")
        gltf = gltf_json(path)
        names = [m.get("name") for m in gltf["meshes"]]
        if names != [f"label_{label['value']}" for label in labels]:
            raise AssertionError(f"{path}: meshes {names}, expected one per label {[l['value'] for l in labels]}")
        colours = [tuple(m["pbrMetallicRoughness"]["baseColorFactor"]) for m in gltf["materials"]]
        if len(set(colours)) != len(labels):
            raise AssertionError(f"{path}: {len(set(colours))} distinct colours for {len(labels)} labels")
    return len(files)


def label_scenes(case):
    """A label map of three touching labels (.npy) as a .glb and a .gltf scene by `cmc33 labels`,
    and the labels its --json lists."""
    seg = case.path("labels.npy")
    z, y, x = np.mgrid[0:20, 0:22, 0:24]
    lab = np.zeros((20, 22, 24), np.uint8)
    lab[(x - 8) ** 2 + (y - 10) ** 2 + (z - 10) ** 2 < 36] = 1
    lab[(x - 15) ** 2 + (y - 11) ** 2 + (z - 9) ** 2 < 30] = 2
    lab[(x > 18) & (y < 6)] = 3
    np.save(seg, lab)
    scenes, labels = [], None
    for name in ("labels.glb", "labels.gltf"):
        out = case.path(name)
        r = subprocess.run([case.cmc33, "labels", seg, "-o", out, "--json"], capture_output=True, text=True)
        if r.returncode != 0:
            raise AssertionError(f"cmc33 labels -o {name}: exit {r.returncode}: {r.stderr.strip()}")
        labels = json.loads(r.stdout)["labels"]
        scenes.append(out)
    if [label["value"] for label in labels] != [1, 2, 3]:
        raise AssertionError(f"cmc33 labels lists {[label['value'] for label in labels]}, expected 1, 2, 3")
    return scenes, labels


def gltf_json(path):
    """The JSON of a .gltf, or of a .glb's first chunk (glTF 2.0, section 4.4)."""
    with open(path, "rb") as f:
        data = f.read()
    if path.endswith(".gltf"):
        return json.loads(data)
    length = int.from_bytes(data[12:16], "little")
    return json.loads(data[20:20 + length])


# ---- GIfTI ----------------------------------------------------------------------------------

def load_gifti(path):
    try:
        import nibabel as nib
    except ImportError:
        print("skipped: nibabel is not installed (python3-nibabel)")
        sys.exit(SKIP)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        img = nib.load(path)
        arrays = {}
        for d in img.darrays:
            arrays[nib.nifti1.intent_codes.label[d.intent]] = d
        return img, arrays


def check_gii(case):
    p, n, t = case.reference()
    count = 0
    # RAS+ (NIfTI) as it is; the same mesh made in LPS+ (--space lps) comes back in RAS+
    for name, extra in (("ras.gii", ()), ("lps.gii", ("--space", "lps"))):
        path = case.extract(name, *extra)
        img, arrays = load_gifti(path)
        for intent in ("pointset", "triangle", "vector"):
            if intent not in arrays:
                raise AssertionError(f"{path}: no {intent} array ({sorted(arrays)})")
        coords = arrays["pointset"]
        same(f"{path} coordinates", coords.data, p)
        same(f"{path} triangles", arrays["triangle"].data.astype(np.int64), t)
        same(f"{path} normals", arrays["vector"].data, n)
        xform = coords.coordsys
        if xform is None or xform.dataspace != 1 or xform.xformspace != 1 or not np.array_equal(xform.xform, np.eye(4)):
            raise AssertionError(f"{path}: the pointset's transform is not NIFTI_XFORM_SCANNER_ANAT's identity")
        count += 1
    # a mirrored space: x negated, and each triangle's winding reversed, so the outside stays outside
    nrrd = case.path("las.nrrd")
    write_las_nrrd(nrrd)
    p, n, t = case.reference(volume=nrrd, name="las.ply")
    path = case.extract("las.gii", volume=nrrd)
    img, arrays = load_gifti(path)
    same(f"{path} coordinates", arrays["pointset"].data, p * np.float32([-1, 1, 1]))
    same(f"{path} triangles", arrays["triangle"].data.astype(np.int64), t[:, [0, 2, 1]])
    same(f"{path} normals", arrays["vector"].data, n * np.float32([-1, 1, 1]))
    return count + 1


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--cmc33", required=True)
    ap.add_argument("--work", required=True)
    ap.add_argument("--only", required=True, choices=["glb", "validator", "vtp", "gii"])
    args = ap.parse_args()
    work = os.path.join(args.work, args.only)
    os.makedirs(work, exist_ok=True)
    try:
        import nibabel  # noqa: F401  (writes the test volume)
    except ImportError:
        print("skipped: nibabel is not installed (python3-nibabel)")
        return SKIP
    case = Case(args.cmc33, work)
    checks = {"glb": check_glb, "validator": check_validator, "vtp": check_vtp, "gii": check_gii}
    try:
        files = checks[args.only](case)
    except AssertionError as e:
        print(f"FAIL {args.only}: {e}")
        return 1
    print(f"{args.only}: {files} files read back as written")
    return 0


if __name__ == "__main__":
    sys.exit(main())
