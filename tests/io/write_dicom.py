#!/usr/bin/env python3
"""Writes the DICOM series of tests/io/test_dicom.cpp with pydicom, an independent writer.

Usage: write_dicom.py OUTDIR
       write_dicom.py --corpus DIR   (the seeds of fuzz/corpus/dicom)

Each case is a folder OUTDIR/<case>. Beside the readable ones, OUTDIR/<case>.json holds what
pydicom says when it reads the files back: the world position of sample (0, 0, 0) and the world
step of each index axis (x along a row, y down a column, z from slice to slice, the slices sorted
by pydicom's own ImagePositionPatient along the normal), and the samples after Rescale
Slope/Intercept, listed z, then y, then x (x fastest).
"""
import json
import os
import random
import sys

import numpy as np
import pydicom
from pydicom.dataset import Dataset, FileDataset, FileMetaDataset
from pydicom.sequence import Sequence
from pydicom.uid import (CTImageStorage, ExplicitVRBigEndian, ExplicitVRLittleEndian, ImplicitVRLittleEndian,
                         RLELossless, generate_uid)

ENHANCED_CT = "1.2.840.10008.5.1.4.1.1.2.1"
rng = random.Random(38)


def rotation(ax, ay, az):
    cx, sx, cy, sy, cz, sz = np.cos(ax), np.sin(ax), np.cos(ay), np.sin(ay), np.cos(az), np.sin(az)
    rx = np.array([[1, 0, 0], [0, cx, -sx], [0, sx, cx]])
    ry = np.array([[cy, 0, sy], [0, 1, 0], [-sy, 0, cy]])
    rz = np.array([[cz, -sz, 0], [sz, cz, 0], [0, 0, 1]])
    return rz @ ry @ rx


def field(nx, ny, nz):
    """A ball's distance field in stored units (whole numbers), [z][y][x]."""
    z, y, x = np.meshgrid(np.arange(nz), np.arange(ny), np.arange(nx), indexing="ij")
    c = np.array([(nx - 1) / 2, (ny - 1) / 2, (nz - 1) / 2])
    d = np.sqrt(((x - c[0]) * 1.0) ** 2 + ((y - c[1]) * 1.1) ** 2 + ((z - c[2]) * 0.9) ** 2)
    return np.round(600 - 100 * d).astype(np.int64)


def base_dataset(series_uid, study_uid, ts=ExplicitVRLittleEndian, sop_class=CTImageStorage):
    meta = FileMetaDataset()
    meta.MediaStorageSOPClassUID = sop_class
    meta.MediaStorageSOPInstanceUID = generate_uid()
    meta.TransferSyntaxUID = ts
    ds = FileDataset(None, {}, file_meta=meta, preamble=b"\0" * 128)
    ds.is_little_endian = ts != ExplicitVRBigEndian
    ds.is_implicit_VR = ts == ImplicitVRLittleEndian
    ds.SOPClassUID = sop_class
    ds.SOPInstanceUID = meta.MediaStorageSOPInstanceUID
    ds.StudyInstanceUID = study_uid
    ds.SeriesInstanceUID = series_uid
    ds.Modality = "CT"
    ds.PatientName = "Test^Cmc33"
    ds.PatientID = "38"
    return ds


def set_pixels(ds, stored, bits_allocated=16, bits_stored=None, signed=True, big=False):
    ds.SamplesPerPixel = 1
    ds.PhotometricInterpretation = "MONOCHROME2"
    ds.Rows, ds.Columns = stored.shape
    ds.BitsAllocated = bits_allocated
    ds.BitsStored = bits_stored or bits_allocated
    ds.HighBit = ds.BitsStored - 1
    ds.PixelRepresentation = 1 if signed else 0
    dtype = {8: "i1", 16: "i2", 32: "i4"}[bits_allocated]
    if not signed:
        dtype = "u" + dtype[1:]
    data = stored.astype((">" if big else "<") + dtype)
    ds.PixelData = data.tobytes()
    ds["PixelData"].VR = "OB" if bits_allocated == 8 else "OW"


def write_series(folder, values, origin, row, col, step, spacing, series_uid=None, study_uid=None, slope=1, intercept=0,
                 description="", ts=ExplicitVRLittleEndian, names=None, bits_stored=None, signed=True, raw=None,
                 positions=None, skip=(), bits_allocated=16):
    """Writes values[z][y][x] (stored units) as single-frame files, in random order with random names,
    InstanceNumbers that do not follow the position. Returns the file names by slice."""
    os.makedirs(folder, exist_ok=True)
    nz = values.shape[0]
    series_uid = series_uid or generate_uid()
    study_uid = study_uid or generate_uid()
    order = list(range(nz))
    rng.shuffle(order)
    files = []
    for k in range(nz):
        if k in skip:
            files.append(None)
            continue
        ds = base_dataset(series_uid, study_uid, ts)
        ds.SeriesDescription = description
        ds.InstanceNumber = order[k] + 1
        p = positions[k] if positions is not None else np.asarray(origin) + k * np.asarray(step)
        ds.ImagePositionPatient = [f"{v:.6f}" for v in p]
        ds.ImageOrientationPatient = [f"{v:.8f}" for v in list(row) + list(col)]
        ds.PixelSpacing = [f"{spacing[0]:g}", f"{spacing[1]:g}"]
        ds.SliceThickness = "1"
        s = slope[k] if isinstance(slope, (list, tuple)) else slope
        c = intercept[k] if isinstance(intercept, (list, tuple)) else intercept
        ds.RescaleSlope = f"{s:g}"
        ds.RescaleIntercept = f"{c:g}"
        ds.RescaleType = "HU"
        set_pixels(ds, values[k] if raw is None else raw[k], bits_allocated, bits_stored, signed, big=ts == ExplicitVRBigEndian)
        if ts == RLELossless:
            ds.file_meta.TransferSyntaxUID = ExplicitVRLittleEndian
            ds.compress(RLELossless)
        name = names[k] if names else f"{rng.getrandbits(40):010x}"
        ds.save_as(os.path.join(folder, name), write_like_original=False)
        files.append(name)
    return files


def expected(folder, out):
    """What pydicom reads back from the folder's files: frame and rescaled samples."""
    slices = []
    for name in sorted(os.listdir(folder)):
        ds = pydicom.dcmread(os.path.join(folder, name))
        slices.append(ds)
    iop = np.array([float(v) for v in slices[0].ImageOrientationPatient])
    row, col = iop[:3], iop[3:]
    normal = np.cross(row, col)
    slices.sort(key=lambda d: float(np.dot(normal, [float(v) for v in d.ImagePositionPatient])))
    p0 = np.array([float(v) for v in slices[0].ImagePositionPatient])
    p1 = np.array([float(v) for v in slices[-1].ImagePositionPatient])
    ps = [float(v) for v in slices[0].PixelSpacing]
    axes = [list(row * ps[1]), list(col * ps[0]), list((p1 - p0) / (len(slices) - 1))]
    vol = np.stack([d.pixel_array.astype(np.float64) * float(d.RescaleSlope) + float(d.RescaleIntercept) for d in slices])
    json.dump({"origin": list(p0), "axes": axes, "dims": [int(vol.shape[2]), int(vol.shape[1]), int(vol.shape[0])],
               "values": [float(v) for v in vol.ravel()]}, open(out, "w"))


def main():
    out = sys.argv[1]
    os.makedirs(out, exist_ok=True)
    # An oblique, rescaled CT with non-square pixels, shuffled names and InstanceNumbers.
    r = rotation(0.3, -0.2, 0.5)
    row, col, normal = r[:, 0], r[:, 1], r[:, 2]
    spacing = (0.9, 0.6)  # between rows, between columns
    values = field(9, 7, 6)
    write_series(f"{out}/oblique", values, (-20.5, 13.25, 101.0), row, col, 1.25 * normal, spacing, slope=1, intercept=-1024,
                 description="oblique")
    expected(f"{out}/oblique", f"{out}/oblique.json")

    # The same with a whole slope: the output is still integer.
    write_series(f"{out}/slope2", values, (0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 2), (1, 1), slope=2, intercept=-1000)
    expected(f"{out}/slope2", f"{out}/slope2.json")

    # A slope and intercept per slice: float samples.
    write_series(f"{out}/perslice", values, (0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 2), (1, 1),
                 slope=[0.5 + 0.25 * k for k in range(6)], intercept=[-10.5 * k for k in range(6)])
    expected(f"{out}/perslice", f"{out}/perslice.json")

    # A gantry tilt: axial rows and columns, each slice shifted along y (a sheared frame).
    tilt = np.deg2rad(15)
    write_series(f"{out}/tilt", values, (-5, -7, 30), (1, 0, 0), (0, 1, 0), (0, 2 * np.sin(tilt), -2 * np.cos(tilt)), (0.5, 0.8))
    expected(f"{out}/tilt", f"{out}/tilt.json")

    # int16 with BitsStored 12: garbage in the four bits above, to be dropped; signed values.
    small = field(6, 5, 4) - 600 + 1500  # about -300..1500, within 12 bits signed (-2048..2047)
    small = np.clip(small, -2048, 2047)
    raw = (small & 0x0FFF) | 0x5000  # bits 12-15 set to 0101
    raw = raw.astype(np.uint16).view(np.int16)
    write_series(f"{out}/bits12", small, (0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1), (1, 1), bits_stored=12, raw=raw)
    expected_bits = f"{out}/bits12.json"
    expected(f"{out}/bits12", expected_bits)
    # pydicom keeps the garbage bits of a signed 12-bit value in some versions: state the values
    exp = json.load(open(expected_bits))
    exp["values"] = [float(v) for v in small.ravel()]
    json.dump(exp, open(expected_bits, "w"))

    # Explicit VR big endian, implicit VR little endian, RLE lossless: the same samples.
    write_series(f"{out}/bigendian", values, (1, 2, 3), (0, 1, 0), (0, 0, -1), (-1.5, 0, 0), (0.7, 0.7), ts=ExplicitVRBigEndian)
    expected(f"{out}/bigendian", f"{out}/bigendian.json")
    write_series(f"{out}/implicit", values, (1, 2, 3), (1, 0, 0), (0, 1, 0), (0, 0, 1.5), (0.7, 0.7), ts=ImplicitVRLittleEndian)
    expected(f"{out}/implicit", f"{out}/implicit.json")
    write_series(f"{out}/rle", values, (1, 2, 3), (1, 0, 0), (0, 1, 0), (0, 0, 1.5), (0.7, 0.7), ts=RLELossless)
    expected(f"{out}/rle", f"{out}/rle.json")

    # Two series in one folder.
    small = field(5, 4, 3)
    write_series(f"{out}/two", small, (0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1), (1, 1), series_uid="1.2.826.0.1.3680043.38.1",
                 description="Bone")
    write_series(f"{out}/two", small, (0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 2), (1, 1), series_uid="1.2.826.0.1.3680043.38.2",
                 description="Soft")

    # Broken series: a missing slice, a duplicate slice, uneven spacing, mixed sizes, RGB.
    write_series(f"{out}/missing", values, (0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 2), (1, 1), skip=(3,),
                 names=[f"s{k}.dcm" for k in range(6)])
    pos = [(0, 0, 2 * k) for k in range(6)]
    pos[4] = pos[3]
    write_series(f"{out}/duplicate", values, None, (1, 0, 0), (0, 1, 0), None, (1, 1), positions=pos,
                 names=[f"s{k}.dcm" for k in range(6)])
    pos = [(0, 0, z) for z in (0, 1, 2, 3.5, 4.5, 5.5)]
    write_series(f"{out}/uneven", values, None, (1, 0, 0), (0, 1, 0), None, (1, 1), positions=pos,
                 names=[f"s{k}.dcm" for k in range(6)])
    uid = generate_uid()
    write_series(f"{out}/mixed", field(5, 4, 2), (0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1), (1, 1), series_uid=uid,
                 names=["a1.dcm", "a2.dcm"])
    write_series(f"{out}/mixed", field(6, 4, 2), (0, 0, 5), (1, 0, 0), (0, 1, 0), (0, 0, 1), (1, 1), series_uid=uid,
                 names=["b1.dcm", "b2.dcm"])
    os.makedirs(f"{out}/rgb", exist_ok=True)
    for k in range(2):
        ds = base_dataset("1.2.826.0.1.3680043.38.9", "1.2.826.0.1.3680043.38.8")
        ds.ImagePositionPatient = [0, 0, k]
        ds.ImageOrientationPatient = [1, 0, 0, 0, 1, 0]
        ds.PixelSpacing = [1, 1]
        ds.SamplesPerPixel = 3
        ds.PhotometricInterpretation = "RGB"
        ds.PlanarConfiguration = 0
        ds.Rows, ds.Columns = 4, 5
        ds.BitsAllocated, ds.BitsStored, ds.HighBit, ds.PixelRepresentation = 8, 8, 7, 0
        ds.PixelData = bytes(4 * 5 * 3)
        ds.save_as(f"{out}/rgb/c{k}.dcm", write_like_original=False)

    # An Enhanced CT: one multi-frame file, per-frame positions in shuffled order.
    write_enhanced(f"{out}/enhanced.dcm", values, (3, -4, 50), r[:, 0], r[:, 1], 1.5 * r[:, 2], (0.8, 0.5), f"{out}/enhanced.json")


def write_enhanced(path, values, origin, row, col, step, spacing, json_path=None, ts=ExplicitVRLittleEndian, bits=16,
                   signed=True, bits_stored=None, slopes=None):
    nz, ny, nx = values.shape
    ds = base_dataset(generate_uid(), generate_uid(), ts=ts, sop_class=ENHANCED_CT)
    ds.NumberOfFrames = nz
    order = list(range(nz))
    rng.shuffle(order)  # frame f holds slice order[f]
    shared = Dataset()
    orient = Dataset()
    orient.ImageOrientationPatient = [f"{v:.8f}" for v in list(row) + list(col)]
    shared.PlaneOrientationSequence = Sequence([orient])
    measures = Dataset()
    measures.PixelSpacing = [f"{spacing[0]:g}", f"{spacing[1]:g}"]
    measures.SliceThickness = "1"
    shared.PixelMeasuresSequence = Sequence([measures])
    transform = Dataset()
    transform.RescaleSlope = "1"
    transform.RescaleIntercept = "-1024"
    transform.RescaleType = "HU"
    shared.PixelValueTransformationSequence = Sequence([transform])
    ds.SharedFunctionalGroupsSequence = Sequence([shared])
    frames = []
    for f in range(nz):
        item = Dataset()
        pos = Dataset()
        pos.ImagePositionPatient = [f"{v:.6f}" for v in np.asarray(origin) + order[f] * np.asarray(step)]
        item.PlanePositionSequence = Sequence([pos])
        if slopes:
            transform = Dataset()
            transform.RescaleSlope = f"{slopes[order[f]]:g}"
            transform.RescaleIntercept = "0.5"
            item.PixelValueTransformationSequence = Sequence([transform])
        frames.append(item)
    ds.PerFrameFunctionalGroupsSequence = Sequence(frames)
    set_pixels(ds, values[order].reshape(nz * ny, nx), bits, bits_stored, signed, big=ts == ExplicitVRBigEndian)
    ds.Rows, ds.Columns = ny, nx
    if ts == RLELossless:
        ds.file_meta.TransferSyntaxUID = ExplicitVRLittleEndian
        ds.compress(RLELossless)
    ds.save_as(path, write_like_original=False)
    if json_path is None:
        return
    p0 = np.asarray(origin, dtype=float)
    json.dump({"origin": list(p0), "axes": [list(np.asarray(row) * spacing[1]), list(np.asarray(col) * spacing[0]),
                                            list(np.asarray(step, dtype=float))],
               "dims": [nx, ny, nz], "values": [float(v) for v in (values - 1024).ravel()]}, open(json_path, "w"))


def corpus(out):
    """Small seeds for fuzz/fuzz_dicom.cpp: multi-frame files of each transfer syntax and pixel type."""
    os.makedirs(out, exist_ok=True)
    r = rotation(0.1, 0.2, 0.3)
    v = field(4, 3, 3) // 50
    a = dict(origin=(1, 2, 3), row=r[:, 0], col=r[:, 1], step=r[:, 2], spacing=(0.5, 0.7))
    write_enhanced(f"{out}/explicit.dcm", v, **a)
    write_enhanced(f"{out}/implicit.dcm", v, ts=ImplicitVRLittleEndian, **a)
    write_enhanced(f"{out}/bigendian.dcm", v, ts=ExplicitVRBigEndian, **a)
    write_enhanced(f"{out}/rle.dcm", v, ts=RLELossless, **a)
    write_enhanced(f"{out}/bits12.dcm", v, bits_stored=12, **a)
    write_enhanced(f"{out}/uint8.dcm", np.abs(v), bits=8, signed=False, **a)
    write_enhanced(f"{out}/int32.dcm", v * 1000, bits=32, **a)
    write_enhanced(f"{out}/slopes.dcm", v, slopes=[0.5, 1.5, 2.5], **a)
    write_series(f"{out}/single", v[:1], (0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1), (1, 1), names=["single.dcm"])
    os.replace(f"{out}/single/single.dcm", f"{out}/single.dcm")
    os.rmdir(f"{out}/single")


if __name__ == "__main__":
    if len(sys.argv) == 3 and sys.argv[1] == "--corpus":
        corpus(sys.argv[2])
    else:
        main()
