#!/usr/bin/env python3
"""Times reading a DICOM series: cmc33 against pydicom and GDCM's Python binding.

Usage: bench/dicom_read.py [--cmc33 build/cli/cmc33] [--size 512 512 300] [--repeat 5] [--dir DIR]

Writes (once, into DIR, default /tmp/cmc33_bench_dicom_<size>) an int16 CT series of single-frame
files with pydicom: explicit VR little endian, Rescale Intercept -1024, shuffled file names. Then,
with the files in the page cache (one untimed read first), the median of --repeat runs of:

  pydicom   dcmread every file, sort by ImagePositionPatient along the normal, stack pixel_array
            into one int16 array and apply the rescale (what a reader must do to have the volume)
  gdcm      GDCM's Python binding: gdcm.ImageReader per file, the buffer into numpy, sorted and
            stacked likewise (skipped if python3-gdcm is missing)
  cmc33     `cmc33 info DIR --json`, the whole process: reading the series, then info's statistics
            over the samples
  cmc33 nrrd  `cmc33 info` on the same volume as one raw NRRD file: info's statistics and a plain
            read, to tell the DICOM reading apart from the rest of `info`

Prints one JSON object with the seconds of each and the ratio cmc33 DICOM read / the faster peer,
where cmc33's DICOM read is estimated as (cmc33 - cmc33 nrrd) + the NRRD file's read (its bytes
over the page cache's bandwidth are negligible next to the DICOM parsing; we count it as 0, which
makes the ratio an upper bound).
"""
import argparse
import json
import os
import random
import statistics
import subprocess
import sys
import time

import numpy as np
import pydicom
from pydicom.dataset import FileDataset, FileMetaDataset
from pydicom.uid import CTImageStorage, ExplicitVRLittleEndian, generate_uid


def write_series(folder, nx, ny, nz):
    os.makedirs(folder, exist_ok=True)
    rng = np.random.default_rng(38)
    series, study = generate_uid(), generate_uid()
    names = [f"{i:08x}" for i in random.Random(38).sample(range(1 << 30), nz)]
    z, y, x = np.meshgrid(np.arange(1), np.arange(ny), np.arange(nx), indexing="ij")
    for k in range(nz):
        meta = FileMetaDataset()
        meta.MediaStorageSOPClassUID = CTImageStorage
        meta.MediaStorageSOPInstanceUID = generate_uid()
        meta.TransferSyntaxUID = ExplicitVRLittleEndian
        ds = FileDataset(None, {}, file_meta=meta, preamble=b"\0" * 128)
        ds.is_little_endian, ds.is_implicit_VR = True, False
        ds.SOPClassUID, ds.SOPInstanceUID = CTImageStorage, meta.MediaStorageSOPInstanceUID
        ds.StudyInstanceUID, ds.SeriesInstanceUID, ds.Modality = study, series, "CT"
        ds.InstanceNumber = nz - k
        ds.ImagePositionPatient = [-250.0, -250.0, 0.5 * k]
        ds.ImageOrientationPatient = [1, 0, 0, 0, 1, 0]
        ds.PixelSpacing = [0.9765625, 0.9765625]
        ds.SliceThickness = 0.5
        ds.RescaleSlope, ds.RescaleIntercept = 1, -1024
        ds.SamplesPerPixel, ds.PhotometricInterpretation = 1, "MONOCHROME2"
        ds.Rows, ds.Columns = ny, nx
        ds.BitsAllocated, ds.BitsStored, ds.HighBit, ds.PixelRepresentation = 16, 16, 15, 1
        r = np.sqrt((x[0] - nx / 2) ** 2 + (y[0] - ny / 2) ** 2)
        ball = (1024 + 1400 * (r < 0.3 * nx + 20 * np.sin(k / 10))).astype(np.int16)
        ds.PixelData = (ball + rng.integers(0, 40, size=ball.shape, dtype=np.int16)).tobytes()
        ds.save_as(os.path.join(folder, names[k]), write_like_original=False)


def files_of(folder):
    return [os.path.join(folder, n) for n in sorted(os.listdir(folder)) if not n.endswith(".nrrd")]


def sort_key(position, orientation):
    normal = np.cross(orientation[:3], orientation[3:])
    return float(np.dot(normal, position))


def read_pydicom(folder):
    slices = [pydicom.dcmread(f) for f in files_of(folder)]
    o = np.array([float(v) for v in slices[0].ImageOrientationPatient])
    slices.sort(key=lambda d: sort_key(np.array([float(v) for v in d.ImagePositionPatient]), o))
    vol = np.stack([d.pixel_array for d in slices])
    return vol * np.int16(slices[0].RescaleSlope) + np.int16(slices[0].RescaleIntercept)


def read_gdcm(folder):
    import gdcm
    items = []
    for f in files_of(folder):
        r = gdcm.ImageReader()
        r.SetFileName(f)
        if not r.Read():
            raise RuntimeError(f)
        image = r.GetImage()
        o = np.array(image.GetDirectionCosines())
        key = sort_key(np.array(image.GetOrigin()), o)
        dims = image.GetDimensions()
        buffer = image.GetBuffer()  # a str whose bytes come back through surrogateescape
        if isinstance(buffer, str):
            buffer = buffer.encode("utf-8", "surrogateescape")
        samples = np.frombuffer(buffer, dtype=np.int16).reshape(dims[1], dims[0])
        items.append((key, samples))
    items.sort(key=lambda t: t[0])
    return np.stack([s for _, s in items]) - np.int16(1024)


def run_cmc33(cmc33, path):
    subprocess.run([cmc33, "info", path, "--json"], check=True, stdout=subprocess.DEVNULL)


def write_nrrd(folder, vol):
    path = os.path.join(folder, "volume.nrrd")
    if not os.path.exists(path):
        with open(path, "wb") as f:
            f.write(f"NRRD0004\ntype: int16\ndimension: 3\nsizes: {vol.shape[2]} {vol.shape[1]} {vol.shape[0]}\n"
                    f"encoding: raw\nendian: little\n\n".encode())
            f.write(vol.astype("<i2").tobytes())
    return path


def median_time(fn, repeat):
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        fn()
        times.append(time.perf_counter() - start)
    return statistics.median(times)


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--cmc33", default="build/cli/cmc33")
    p.add_argument("--size", type=int, nargs=3, default=[512, 512, 300])
    p.add_argument("--repeat", type=int, default=5)
    p.add_argument("--dir")
    a = p.parse_args()
    nx, ny, nz = a.size
    folder = a.dir or f"/tmp/cmc33_bench_dicom_{nx}x{ny}x{nz}"
    if not os.path.isdir(folder) or len(os.listdir(folder)) < nz:
        write_series(folder, nx, ny, nz)
    vol = read_pydicom(folder)  # also warms the page cache
    nrrd = write_nrrd(folder, vol)
    result = {"series": f"{nx}x{ny}x{nz} int16, {nz} files", "repeat": a.repeat}
    result["pydicom_s"] = median_time(lambda: read_pydicom(folder), a.repeat)
    try:
        import gdcm  # noqa: F401
        assert np.array_equal(read_gdcm(folder), vol)
        result["gdcm_python_s"] = median_time(lambda: read_gdcm(folder), a.repeat)
    except ImportError:
        result["gdcm_python_s"] = None
    # the DICOM folder is the input; the NRRD file beside it is not a DICOM file and is skipped
    result["cmc33_info_dicom_s"] = median_time(lambda: run_cmc33(a.cmc33, folder), a.repeat)
    result["cmc33_info_nrrd_s"] = median_time(lambda: run_cmc33(a.cmc33, nrrd), a.repeat)
    read = result["cmc33_info_dicom_s"] - result["cmc33_info_nrrd_s"]
    peers = [t for t in (result["pydicom_s"], result["gdcm_python_s"]) if t]
    result["cmc33_dicom_read_s"] = read
    result["ratio_to_fastest_peer"] = read / min(peers)
    print(json.dumps(result, indent=1))


if __name__ == "__main__":
    sys.exit(main())
