#!/usr/bin/python3
"""Volumes written by independent writers (nibabel for NIfTI, numpy for .npy, VTK for .vti) are
meshed by `cmc33 extract`, and each mesh is compared with the mesh of the same samples in index
space (a NRRD with no frame) mapped to world coordinates by the writer's own library: nibabel's
img.affine, VTK's TransformContinuousIndexToPhysicalPoint. The triangles must be the same and the
vertices equal to float precision.

Usage: independent_writers.py --cmc33 PATH --work DIR [--only nifti|npy|vti]
Exit 77 (CTest: skipped) when a writer's Python package is missing.
"""

import argparse
import os
import subprocess
import sys

SKIP = 77
try:
    import numpy as np
except ImportError:
    print("skipped: numpy is not installed (python3-numpy)")
    sys.exit(SKIP)


def ply_vertices(path):
    """(vertices (n, 3) float64, triangle count) of an ASCII PLY written by cmc33."""
    with open(path, "rb") as f:
        data = f.read()
    header, body = data.split(b"end_header\n", 1)
    nv = nf = 0
    for line in header.decode().splitlines():
        words = line.split()
        if words[:2] == ["element", "vertex"]:
            nv = int(words[2])
        if words[:2] == ["element", "face"]:
            nf = int(words[2])
    lines = body.decode().splitlines()
    verts = np.array([[float(w) for w in lines[i].split()[:3]] for i in range(nv)], dtype=np.float64)
    return verts.reshape(-1, 3), nf


def extract(cmc33, path, iso, out, extra=()):
    cmd = [cmc33, "extract", path, "--iso", repr(float(iso)), "-o", out, "--ascii", "--quiet", *extra]
    run = subprocess.run(cmd, capture_output=True, text=True)
    if run.returncode != 0:
        raise AssertionError(f"{' '.join(cmd)} failed ({run.returncode}): {run.stderr.strip()}")
    return ply_vertices(out)


def write_index_nrrd(path, samples_xyz):
    """`samples_xyz[i, j, k]` as a NRRD with no frame: sample (i, j, k) at (i, j, k)."""
    a = np.asarray(samples_xyz, dtype=np.float64)
    header = ("NRRD0004\ntype: double\ndimension: 3\nsizes: %d %d %d\nendian: little\nencoding: raw\n\n" % a.shape)
    with open(path, "wb") as f:
        f.write(header.encode())
        f.write(a.astype("<f8").tobytes(order="F"))  # i fastest


def field(shape, seed=0):
    """A smooth field with a closed surface near 0.5 and some detail, shape (nx, ny, nz)."""
    rng = np.random.default_rng(seed)
    grids = np.meshgrid(*[np.linspace(-1, 1, n) for n in shape], indexing="ij")
    r = np.sqrt(sum((g * s) ** 2 for g, s in zip(grids, (1.0, 1.2, 0.9))))
    return (1.2 - r + 0.05 * rng.standard_normal(shape)).astype(np.float64)


class Checker:
    def __init__(self, cmc33, work):
        self.cmc33, self.work, self.failures, self.count = cmc33, work, [], 0

    def compare(self, name, path, samples_xyz, iso, to_world, extra=(), reference_extra=()):
        """Meshes `path` and the NRRD of `samples_xyz`; vertices of the first must be to_world(second)."""
        self.count += 1
        try:
            ref_path = os.path.join(self.work, name + ".ref.nrrd")
            write_index_nrrd(ref_path, samples_xyz)
            ref, ref_tris = extract(self.cmc33, ref_path, iso, os.path.join(self.work, name + ".ref.ply"), reference_extra)
            got, tris = extract(self.cmc33, path, iso, os.path.join(self.work, name + ".ply"), extra)
            if tris == 0 or tris != ref_tris:
                raise AssertionError(f"{tris} triangles, the index-space mesh has {ref_tris}")
            want = to_world(ref)
            if want.shape != got.shape:
                raise AssertionError(f"{got.shape[0]} vertices, expected {want.shape[0]}")
            scale = max(1.0, float(np.abs(want).max()))
            err = float(np.abs(got - want).max())
            if err > 4e-6 * scale:  # float32 positions: ~6e-8 relative, with room for the frame's rounding
                raise AssertionError(f"vertices differ from the writer's world coordinates by up to {err:g} (scale {scale:g})")
            print(f"ok   {name}: {tris} triangles, max deviation {err:.3g}")
        except AssertionError as e:
            self.failures.append(f"{name}: {e}")
            print(f"FAIL {name}: {e}")

    def refuse(self, name, path, expected, extra=()):
        """`cmc33 info` must exit 1 with a message containing `expected`."""
        self.count += 1
        run = subprocess.run([self.cmc33, "info", path, *extra], capture_output=True, text=True)
        if run.returncode != 1 or expected not in run.stderr:
            self.failures.append(f"{name}: exit {run.returncode}, stderr {run.stderr.strip()!r}, expected {expected!r}")
            print(f"FAIL {name}")
        else:
            print(f"ok   {name}: {run.stderr.strip()}")


def affine_map(affine):
    A = np.asarray(affine, dtype=np.float64)
    return lambda v: v @ A[:3, :3].T + A[:3, 3]


def check_nifti(c):
    try:
        import nibabel as nib
    except ImportError:
        return False
    shape = (11, 9, 8)
    data = field(shape, 1).astype(np.float32)
    # oblique, sheared, non-unit, with a flip: sform != qform
    sform = np.array([[0.9, 0.2, 0.1, -40.5], [-0.15, 1.1, 0.3, 12.25], [0.05, -0.25, -1.3, 7.0], [0, 0, 0, 1]])
    theta = 0.3
    rot = np.array([[np.cos(theta), -np.sin(theta), 0], [np.sin(theta), np.cos(theta), 0], [0, 0, 1]])
    qform = np.eye(4)
    qform[:3, :3] = rot @ np.diag([1.5, 0.8, -2.0])  # negative determinant: qfac -1
    qform[:3, 3] = [5.0, -3.0, 20.0]

    def save(img, name):
        path = os.path.join(c.work, name)
        nib.save(img, path)
        return path, nib.load(path)

    # NIfTI-1 and NIfTI-2, sform and qform both set: the sform wins
    for cls, tag in ((nib.Nifti1Image, "nifti1"), (nib.Nifti2Image, "nifti2")):
        img = cls(data, None)
        img.set_qform(qform, code=1)
        img.set_sform(sform, code=2)
        path, back = save(img, f"{tag}_sform.nii")
        assert np.allclose(back.affine, sform, atol=1e-6) and not np.allclose(back.get_qform(), sform)
        c.compare(f"{tag} sform != qform", path, np.asanyarray(back.dataobj), 0.5, affine_map(back.affine))
    # qform only (negative qfac), and the LPS conversion of the same file
    img = nib.Nifti1Image(data, None)
    img.set_qform(qform, code=1)
    img.set_sform(None, code=0)
    path, back = save(img, "qform_only.nii")
    assert int(back.header["sform_code"]) == 0 and float(back.header["pixdim"][0]) == -1
    c.compare("nifti1 qform only, qfac -1", path, np.asanyarray(back.dataobj), 0.5, affine_map(back.affine))
    lps = np.diag([-1.0, -1.0, 1.0, 1.0]) @ back.affine
    c.compare("nifti1 qform only --space lps", path, np.asanyarray(back.dataobj), 0.5, affine_map(lps), extra=("--space", "lps"))
    # gzip, big-endian, the .hdr/.img pair (named by either file)
    img = nib.Nifti1Image(data.astype(">f4"), sform)
    img.header.set_data_dtype(">f4")
    path, back = save(img, "big_endian.nii.gz")
    c.compare("nifti1 .nii.gz", path, np.asanyarray(back.dataobj), 0.5, affine_map(back.affine))
    big = nib.Nifti1Image(data, sform, header=nib.Nifti1Header(endianness=">"))
    path, back = save(big, "big_endian.nii")
    assert back.header.endianness == ">"
    c.compare("nifti1 big-endian", path, np.asanyarray(back.dataobj), 0.5, affine_map(back.affine))
    pair = nib.Nifti1Pair(data, sform)
    path, back = save(pair, "pair.hdr")
    c.compare("nifti1 pair .hdr", path, np.asanyarray(back.dataobj), 0.5, affine_map(back.affine))
    c.compare("nifti1 pair .img", path[:-4] + ".img", np.asanyarray(back.dataobj), 0.5, affine_map(back.affine))
    pair2 = nib.Nifti2Pair(data, sform)
    path, back = save(pair2, "pair2.hdr")
    c.compare("nifti2 pair .hdr", path, np.asanyarray(back.dataobj), 0.5, affine_map(back.affine))
    # a compressed pair: nibabel writes pair.hdr.gz and pair.img.gz
    path, back = save(nib.Nifti1Pair(data, sform), "packed.hdr.gz")
    c.compare("nifti1 pair .hdr.gz + .img.gz", path, np.asanyarray(back.dataobj), 0.5, affine_map(back.affine))
    # scl_slope / scl_inter on stored int16, uint8 and int32
    for dtype, slope, inter in ((np.int16, 0.004, -1.5), (np.uint8, 0.01, -0.2), (np.int32, 2e-5, 0.25)):
        stored = np.round((data - data.min()) / (data.max() - data.min()) * (100 if dtype == np.uint8 else 1000)).astype(dtype)
        img = nib.Nifti1Image(stored, sform)
        img.header.set_data_dtype(dtype)
        path, back = save(img, f"scaled_{np.dtype(dtype).name}.nii")
        with open(path, "r+b") as f:  # scl_slope, scl_inter: float32 at bytes 112 and 116 (nifti1.h)
            f.seek(112)
            f.write(np.array([slope, inter], dtype="<f4").tobytes())
        back = nib.load(path)
        values = np.asanyarray(back.dataobj)
        assert not np.array_equal(values, stored)
        iso = float(np.median(values))
        c.compare(f"nifti1 {np.dtype(dtype).name} scl_slope {slope} scl_inter {inter}", path, values, iso, affine_map(back.affine))
    # other stored types
    for dtype in (np.int8, np.uint16, np.float64, np.uint32):
        stored = np.round((data - data.min()) / (data.max() - data.min()) * 100).astype(dtype)
        img = nib.Nifti1Image(stored, sform, dtype=dtype)
        path, back = save(img, f"type_{np.dtype(dtype).name}.nii")
        c.compare(f"nifti1 {np.dtype(dtype).name}", path, np.asanyarray(back.dataobj), 50.5, affine_map(back.affine))
    # 4-D: --frame N reads img.dataobj[..., N]
    frames = np.stack([field(shape, s).astype(np.float32) for s in (2, 3, 4)], axis=-1)
    for name in ("four_d.nii", "four_d.nii.gz"):
        path, back = save(nib.Nifti1Image(frames, sform), name)
        for n in (1, 2):
            c.compare(f"nifti1 4-D {name} --frame {n}", path, np.asanyarray(back.dataobj)[..., n], 0.5, affine_map(back.affine),
                      extra=("--frame", str(n)))
        c.refuse(f"nifti1 4-D {name} without --frame", path, "choose one with --frame N")
    # refused by name
    rgb = np.zeros(shape, dtype=[("R", "u1"), ("G", "u1"), ("B", "u1")])
    path, _ = save(nib.Nifti1Image(rgb, sform), "rgb.nii")
    c.refuse("nifti1 RGB24", path, "RGB24")
    path, _ = save(nib.Nifti1Image(np.zeros(shape, np.complex64), sform), "complex.nii")
    c.refuse("nifti1 complex64", path, "complex64")
    path, _ = save(nib.Nifti1Image(np.zeros((5, 4), np.float32), np.eye(4)), "flat.nii")
    c.refuse("nifti1 2-D", path, "cmc33 meshes 3-D volumes")
    return True


def check_npy(c):
    shape_zyx = (8, 9, 11)
    base = field(shape_zyx[::-1], 5).transpose(2, 1, 0)  # arr[z, y, x]
    xyz = lambda arr: np.asarray(arr, dtype=np.float64).transpose(2, 1, 0)
    identity = lambda v: v
    for dtype, order, version in (("<f4", "C", (1, 0)), (">f8", "F", (1, 0)), ("<i2", "F", (2, 0)), (">u2", "C", (3, 0)),
                                  ("|u1", "C", (1, 0)), ("|i1", "F", (1, 0)), ("<i8", "C", (1, 0)), (">u4", "C", (2, 0)),
                                  ("<f2", "F", (1, 0)), ("<u8", "F", (1, 0))):
        if dtype[1] == "f":
            arr = base.astype(dtype)
            iso = 0.5
        else:
            arr = np.round((base - base.min()) / (base.max() - base.min()) * 100).astype(dtype)
            iso = 50.5
        arr = np.asfortranarray(arr) if order == "F" else np.ascontiguousarray(arr)
        path = os.path.join(c.work, f"array_{dtype[1:]}_{order}.npy")
        with open(path, "wb") as f:
            np.lib.format.write_array(f, arr, version=version)
        c.compare(f"npy {dtype} {order} order, version {version[0]}.0", path, xyz(arr), iso, identity)
    # --spacing and --origin give the frame the file has not
    path = os.path.join(c.work, "array_f4_C.npy")
    arr = np.load(path)
    spacing, origin = np.array([0.5, 2.0, 1.25]), np.array([-3.0, 4.5, 10.0])
    c.compare("npy --spacing --origin", path, xyz(arr), 0.5, lambda v: v * spacing + origin,
              extra=("--spacing", *map(str, spacing), "--origin", *map(str, origin)))
    # a stack arr[t, z, y, x]
    stack = np.stack([base.astype(np.float32), (base * 0.9).astype(np.float32)])
    for order in ("C", "F"):
        path = os.path.join(c.work, f"stack_{order}.npy")
        np.save(path, np.asfortranarray(stack) if order == "F" else stack)
        c.compare(f"npy 4-D {order} order --frame 1", path, xyz(stack[1]), 0.5, identity, extra=("--frame", "1"))
    for name, arr, expected in (("bool", np.zeros(shape_zyx, bool), "bool"), ("complex", np.zeros(shape_zyx, np.complex64), "complex"),
                                ("structured", np.zeros(shape_zyx, [("a", "<f4"), ("b", "<f4")]), "structured")):
        path = os.path.join(c.work, f"refused_{name}.npy")
        np.save(path, arr)
        c.refuse(f"npy {name}", path, expected)
    path = os.path.join(c.work, "object.npy")
    np.save(path, np.empty(shape_zyx, dtype=object), allow_pickle=True)
    c.refuse("npy object", path, "Python objects")
    return True


def check_vti(c):
    try:
        import vtk
        from vtk.util import numpy_support
    except ImportError:
        return False
    nx, ny, nz = 11, 9, 8
    values = field((nx, ny, nz), 7)
    theta = 0.4
    direction = np.array([[np.cos(theta), 0, np.sin(theta)], [0, 1, 0], [-np.sin(theta), 0, np.cos(theta)]]) @ np.diag([1, -1, 1])
    origin, spacing = (3.5, -2.0, 11.0), (0.7, 1.3, 2.1)

    def stored(dtype):
        return (values if np.dtype(dtype).kind == "f" else np.round(values * 100)).astype(dtype)

    def image(dtype):
        img = vtk.vtkImageData()
        img.SetDimensions(nx, ny, nz)
        img.SetOrigin(*origin)
        img.SetSpacing(*spacing)
        img.SetDirectionMatrix(*direction.flatten())
        arr = numpy_support.numpy_to_vtk(stored(dtype).ravel(order="F"), deep=True)
        arr.SetName("density")
        img.GetPointData().SetScalars(arr)
        return img

    def to_world(img):
        def world(v):
            out = np.empty_like(v)
            for n, p in enumerate(v):
                q = [0.0, 0.0, 0.0]
                img.TransformContinuousIndexToPhysicalPoint(list(p), q)
                out[n] = q
            return out
        return world

    modes = [("ascii", None, None, None), ("binary", None, 32, None), ("binary", "zlib", 64, None),
             ("binary", "zlib", 32, None), ("appended", None, 64, True), ("appended", None, 32, False),
             ("appended", "zlib", 64, False), ("appended", "zlib", 32, True)]
    for n, (mode, compressor, header, base64) in enumerate(modes):
        dtype = (np.float32, np.float64, np.int16, np.uint8)[n % 4]
        img = image(dtype)
        w = vtk.vtkXMLImageDataWriter()
        path = os.path.join(c.work, f"image_{n}_{mode}.vti")
        w.SetFileName(path)
        w.SetInputData(img)
        {"ascii": w.SetDataModeToAscii, "binary": w.SetDataModeToBinary, "appended": w.SetDataModeToAppended}[mode]()
        if compressor is None:
            w.SetCompressorTypeToNone()
        else:
            w.SetCompressorTypeToZLib()
            w.SetBlockSize(256)  # several blocks
        if header == 64:
            w.SetHeaderTypeToUInt64()
        elif header == 32:
            w.SetHeaderTypeToUInt32()
        if base64 is not None:
            w.SetEncodeAppendedData(base64)
        assert w.Write() == 1
        samples = stored(dtype).astype(np.float64)
        iso = 0.5 if dtype in (np.float32, np.float64) else 50.5
        c.compare(f"vti {mode} {compressor or 'raw'} UInt{header} {'base64' if base64 else ''} {np.dtype(dtype).name}", path, samples,
                  iso, to_world(img))
    return True


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--cmc33", required=True)
    p.add_argument("--work", required=True)
    p.add_argument("--only", choices=["nifti", "npy", "vti"])
    a = p.parse_args()
    os.makedirs(a.work, exist_ok=True)
    c = Checker(a.cmc33, a.work)
    missing = []
    for name, check in (("nifti", check_nifti), ("npy", check_npy), ("vti", check_vti)):
        if a.only and a.only != name:
            continue
        if not check(c):
            missing.append(name)
    if c.failures:
        print(f"{len(c.failures)} of {c.count} checks failed", file=sys.stderr)
        return 1
    if missing:
        print(f"skipped: the writers of {', '.join(missing)} are not installed (python3-nibabel, python3-vtk9)")
        return SKIP
    print(f"all {c.count} checks passed")
    return 0


if __name__ == "__main__":
    sys.exit(main())
