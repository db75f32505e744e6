#!/usr/bin/python3
"""Writes the seed corpora fuzz/corpus/nifti, npy and vti with nibabel, numpy and VTK: small
volumes of several types, gzip, 4-D, qform only, sform, big-endian, NIfTI-2, a .hdr/.img pair
(fuzz_nifti.cpp's layout: a frame byte, the file, "\\0IMG\\0", the .img), C and Fortran order, each
.npy version. Run from the repository's root: /usr/bin/python3 fuzz/make_corpus_nifti_npy.py"""

import gzip
import io
import os

import nibabel as nib
import numpy as np

root = os.path.join(os.path.dirname(os.path.abspath(__file__)), "corpus")
rng = np.random.default_rng(38)


def put(folder, name, data):
    os.makedirs(os.path.join(root, folder), exist_ok=True)
    with open(os.path.join(root, folder, name), "wb") as f:
        f.write(data)


shape = (3, 3, 2)
sform = np.array([[0.9, 0.1, 0, -4], [0, 1.1, 0.2, 2], [0.1, 0, -1.3, 7], [0, 0, 0, 1]])
for dtype in (np.uint8, np.int16, np.float32, np.float64, np.int64, np.uint16):
    img = nib.Nifti1Image((rng.random(shape) * 50).astype(dtype), sform, dtype=dtype)
    put("nifti", f"n1_{np.dtype(dtype).name}.nii", b"\0" + img.to_bytes())
img = nib.Nifti1Image(rng.random(shape).astype(np.float32), None)
img.set_qform(np.diag([1.5, 0.8, -2.0, 1]), code=1)
img.set_sform(None, code=0)
put("nifti", "n1_qform_only.nii", b"\0" + img.to_bytes())
img = nib.Nifti1Image(rng.random(shape).astype(np.float32), sform, header=nib.Nifti1Header(endianness=">"))
put("nifti", "n1_big_endian.nii", b"\0" + img.to_bytes())
img = nib.Nifti1Image((rng.random(shape) * 100).astype(np.int16), sform, dtype=np.int16)
img.header.set_slope_inter(0.5, -3)
raw = bytearray(img.to_bytes())
raw[112:120] = np.array([0.5, -3], "<f4").tobytes()
put("nifti", "n1_scaled.nii", b"\0" + bytes(raw))
frames = rng.random(shape + (3,)).astype(np.float32)
img = nib.Nifti1Image(frames, sform)
put("nifti", "n1_4d_frame1.nii", b"\1" + img.to_bytes())
put("nifti", "n1_4d_frame2.nii.gz", b"\2" + gzip.compress(img.to_bytes(), mtime=0))
put("nifti", "n1_gz.nii.gz", b"\0" + gzip.compress(nib.Nifti1Image(rng.random(shape).astype(np.float32), sform).to_bytes(), mtime=0))
put("nifti", "n2_sform.nii", b"\0" + nib.Nifti2Image(rng.random(shape).astype(np.float32), sform).to_bytes())
pair = nib.Nifti1Pair(rng.random(shape).astype(np.float32), sform)
hdr = pair.header.copy()
hdr.set_data_shape(shape)
hdr.set_data_dtype(np.float32)
put("nifti", "n1_pair.hdr", b"\0" + hdr.binaryblock + b"\0IMG\0" + np.asarray(pair.dataobj, "<f4").tobytes(order="F"))

base = rng.random((2, 3, 3))
for n, (dtype, order, version) in enumerate((("<f4", "C", (1, 0)), (">f8", "F", (1, 0)), ("<i2", "C", (2, 0)), ("|u1", "F", (3, 0)),
                                            ("<f2", "C", (1, 0)), ("<i8", "C", (1, 0)))):
    arr = (base * 100).astype(dtype)
    arr = np.asfortranarray(arr) if order == "F" else arr
    f = io.BytesIO()
    np.lib.format.write_array(f, arr, version=version)
    put("npy", f"array_{n}_{dtype[1:]}_{order}.npy", b"\0" + f.getvalue())
f = io.BytesIO()
np.lib.format.write_array(f, np.stack([base, base * 2]).astype("<f4"))
put("npy", "stack_frame1.npy", b"\1" + f.getvalue())

# .vti (fuzz_vti.cpp: an --array byte, then the file), written by VTK in each data mode
try:
    import vtk
    from vtk.util import numpy_support
except ImportError:
    vtk = None
if vtk is not None:
    import tempfile

    for n, (mode, zlib, header, b64) in enumerate((("ascii", False, 32, None), ("binary", False, 32, None), ("binary", True, 64, None),
                                                   ("appended", False, 64, True), ("appended", True, 32, False))):
        img = vtk.vtkImageData()
        img.SetDimensions(3, 3, 2)
        img.SetOrigin(1, -2, 3)
        img.SetSpacing(0.5, 1, 2)
        img.SetDirectionMatrix(0, 1, 0, -1, 0, 0, 0, 0, 1)
        arr = numpy_support.numpy_to_vtk((rng.random(18) * 100).astype((np.float32, np.int16)[n % 2]), deep=True)
        arr.SetName("density")
        img.GetPointData().SetScalars(arr)
        w = vtk.vtkXMLImageDataWriter()
        with tempfile.TemporaryDirectory() as tmp:
            path = os.path.join(tmp, "a.vti")
            w.SetFileName(path)
            w.SetInputData(img)
            {"ascii": w.SetDataModeToAscii, "binary": w.SetDataModeToBinary, "appended": w.SetDataModeToAppended}[mode]()
            w.SetCompressorTypeToZLib() if zlib else w.SetCompressorTypeToNone()
            w.SetBlockSize(32)
            w.SetHeaderTypeToUInt64() if header == 64 else w.SetHeaderTypeToUInt32()
            if b64 is not None:
                w.SetEncodeAppendedData(b64)
            w.Write()
            with open(path, "rb") as f:
                put("vti", f"image_{n}_{mode}{'_zlib' if zlib else ''}.vti", bytes([n % 2]) + f.read())
