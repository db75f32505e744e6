#!/usr/bin/env python3
"""Writes the TIFF stacks of tests/io/test_tiff.cpp with tifffile, an independent writer.

Usage: write_tiff.py OUTDIR
       write_tiff.py --corpus DIR   (the seeds of fuzz/corpus/tiff)

Beside each readable case, OUTDIR/<case>.json holds what tifffile reads back: the samples listed z,
then y, then x (x fastest: numpy's volume[z, y, x] flattened), and the spacing the case declares.
"""
import json
import os
import sys

import numpy as np
import tifffile


def field(nx, ny, nz):
    z, y, x = np.meshgrid(np.arange(nz), np.arange(ny), np.arange(nx), indexing="ij")
    c = np.array([(nx - 1) / 2, (ny - 1) / 2, (nz - 1) / 2])
    return 600 - 100 * np.sqrt((x - c[0]) ** 2 + ((y - c[1]) * 1.2) ** 2 + ((z - c[2]) * 0.8) ** 2)


def save_expected(out, name, volume, spacing):
    json.dump({"dims": [volume.shape[2], volume.shape[1], volume.shape[0]], "spacing": spacing,
               "values": [float(v) for v in volume.ravel()]}, open(f"{out}/{name}.json", "w"))


def main():
    out = sys.argv[1]
    os.makedirs(out, exist_ok=True)
    f = field(11, 9, 7)

    # A multi-page ImageJ stack: x/y from the resolution tags (pixels per unit), z from spacing=.
    u16 = np.round(np.clip(f + 200, 0, None)).astype(np.uint16)
    tifffile.imwrite(f"{out}/imagej.tif", u16, imagej=True, resolution=(1 / 0.5, 1 / 0.25),
                     metadata={"spacing": 2.5, "unit": "um", "axes": "ZYX"})
    save_expected(out, "imagej", tifffile.imread(f"{out}/imagej.tif"), [0.5, 0.25, 2.5])

    # float32, tiled and deflate-compressed, plain TIFF (spacing 1 1 1).
    f32 = f.astype(np.float32)
    tifffile.imwrite(f"{out}/float.tif", f32, tile=(16, 16), compression="zlib")
    save_expected(out, "float", tifffile.imread(f"{out}/float.tif"), [1, 1, 1])

    # int16 in strips of 2 rows, deflate, big-endian; and a BigTIFF of int32.
    i16 = np.round(f - 300).astype(np.int16)
    tifffile.imwrite(f"{out}/strips.tif", i16, rowsperstrip=2, compression="zlib", byteorder=">")
    save_expected(out, "strips", tifffile.imread(f"{out}/strips.tif"), [1, 1, 1])
    i32 = np.round(f * 1000).astype(np.int32)
    tifffile.imwrite(f"{out}/big.tif", i32, bigtiff=True)
    save_expected(out, "big", tifffile.imread(f"{out}/big.tif"), [1, 1, 1])

    # OME-TIFF with PhysicalSize.
    tifffile.imwrite(f"{out}/ome.ome.tif", u16, ome=True,
                     metadata={"axes": "ZYX", "PhysicalSizeX": 0.3, "PhysicalSizeY": 0.4, "PhysicalSizeZ": 1.7})
    save_expected(out, "ome", tifffile.imread(f"{out}/ome.ome.tif"), [0.3, 0.4, 1.7])

    # An ImageJ hyperstack of 3 time frames: --frame picks one.
    t = np.stack([u16, u16 + 1000, u16 + 2000])
    tifffile.imwrite(f"{out}/frames.tif", t, imagej=True, metadata={"axes": "TZYX", "spacing": 3.0})
    save_expected(out, "frames1", t[1], [1, 1, 3.0])

    # A folder of single-page slices numbered without zero padding (2 sorts after 10 by name).
    os.makedirs(f"{out}/folder", exist_ok=True)
    for k in range(u16.shape[0]):
        tifffile.imwrite(f"{out}/folder/slice{k + 1}.tif", u16[k])
    save_expected(out, "folder", u16, [1, 1, 1])

    # Refused: a gap in the numbering, mixed sizes, RGB, two channels.
    os.makedirs(f"{out}/gap", exist_ok=True)
    for k in (1, 2, 3, 5, 6):
        tifffile.imwrite(f"{out}/gap/s_{k:03d}.tif", u16[0])
    os.makedirs(f"{out}/sizes", exist_ok=True)
    tifffile.imwrite(f"{out}/sizes/a1.tif", u16[0])
    tifffile.imwrite(f"{out}/sizes/a2.tif", u16[0, :, :5])
    tifffile.imwrite(f"{out}/rgb.tif", np.zeros((3, 8, 8, 3), np.uint8), photometric="rgb")
    tifffile.imwrite(f"{out}/channels.tif", np.zeros((4, 2, 8, 8), np.uint16), imagej=True, metadata={"axes": "ZCYX"})


def corpus(out):
    """Small seeds for fuzz/fuzz_tiff.cpp: each page layout, sample type and description."""
    os.makedirs(out, exist_ok=True)
    f = field(5, 4, 3)
    u16 = np.round(np.clip(f + 200, 0, None)).astype(np.uint16)
    tifffile.imwrite(f"{out}/uint8.tif", u16.astype(np.uint8))
    tifffile.imwrite(f"{out}/imagej.tif", u16, imagej=True, resolution=(2, 4), metadata={"spacing": 2.5, "unit": "um", "axes": "ZYX"})
    tifffile.imwrite(f"{out}/tiled.tif", f.astype(np.float32), tile=(16, 16), compression="zlib")
    tifffile.imwrite(f"{out}/strips_be.tif", np.round(f).astype(np.int16), rowsperstrip=1, byteorder=">")
    tifffile.imwrite(f"{out}/bigtiff.tif", f.astype(np.float64), bigtiff=True)
    tifffile.imwrite(f"{out}/ome.tif", u16, ome=True, metadata={"axes": "ZYX", "PhysicalSizeX": 0.3, "PhysicalSizeZ": 1.7})
    tifffile.imwrite(f"{out}/frames.tif", np.stack([u16, u16]), imagej=True, metadata={"axes": "TZYX"})
    tifffile.imwrite(f"{out}/int32.tif", np.round(f * 100).astype(np.int32), compression="zlib")
    tifffile.imwrite(f"{out}/rgb.tif", np.zeros((2, 4, 4, 3), np.uint8), photometric="rgb")


if __name__ == "__main__":
    if len(sys.argv) == 3 and sys.argv[1] == "--corpus":
        corpus(sys.argv[2])
    else:
        main()
