#!/usr/bin/env python3
"""Writes the seed corpus of the fuzz targets: a few tiny valid files per reader (both byte
orders, gzip/zlib where the format has it, ASCII and binary), into fuzz/corpus/<target>/.
Run from anywhere: python3 fuzz/make_corpus.py. Files found by fuzzing (crash-*, regression
inputs) live beside the seeds and are not touched; the seeds are rewritten identically."""

import gzip
import os
import struct
import zlib

HERE = os.path.dirname(os.path.abspath(__file__))


def put(target, name, data):
    folder = os.path.join(HERE, "corpus", target)
    os.makedirs(folder, exist_ok=True)
    with open(os.path.join(folder, name), "wb") as f:
        f.write(data)


def gz(data):
    return gzip.compress(data, compresslevel=9, mtime=0)


def samples(fmt, values):
    return struct.pack(fmt[0] + fmt[1] * len(values), *values)


U16 = [0, 1, 258, 0x7FFF, 0x8000, 0xFFFF, 12345, 54321]
F32 = [0.0, 1.5, -2.25, 3.0, 100.0, -0.5, 7.0, 8.0]
TEXT = b"0 1 258 32767\n32768 65535 12345 54321\n"

# ---- NRRD (attached) ------------------------------------------------------------------------
nrrd = b"NRRD0004\n# c\ntype: %s\ndimension: 3\nsizes: 2 2 2\n"
put("nrrd", "u16_le_raw.nrrd", nrrd % b"ushort" + b"endian: little\nencoding: raw\n"
    b"spacings: 1 2 3\n\n" + samples("<H", U16))
put("nrrd", "f32_be_raw.nrrd", nrrd % b"float" + b"endian: big\nencoding: raw\n"
    b"space directions: (1,0,0) (0,2,0) (0,0,3)\nspace origin: (1,2,3)\n\n" + samples(">f", F32))
put("nrrd", "u16_le_gzip.nrrd", nrrd % b"uint16" + b"endian: little\nencoding: gzip\n\n"
    + gz(samples("<H", U16)))
put("nrrd", "i16_be_gzip_skip.nrrd", nrrd % b"short" + b"endian: big\nencoding: gz\nbyte skip: 4\n\n"
    + gz(b"abcd" + samples(">h", [1, -2, 3, -4, 5, -6, 7, -8])))
put("nrrd", "u16_ascii.nrrd", nrrd % b"unsigned short" + b"encoding: ascii\n\n" + TEXT)
put("nrrd", "u8_lineskip.nrrd", nrrd % b"uchar" + b"encoding: raw\nline skip: 1\nkey:=value\n\n"
    b"skipped line\n" + bytes(range(8)))
put("nrrd", "f64_byteskip_end.nrrd", nrrd % b"double" + b"endian: little\nencoding: raw\n"
    b"byte skip: -1\n\nxx" + samples("<d", F32))

# ---- NRRD (detached): header, NUL, data file ------------------------------------------------
nhdr = b"NRRD0004\ntype: %s\ndimension: 3\nsizes: 2 2 2\ndata file: %s\n"
put("nhdr", "u16_le_raw.nhdr", nhdr % (b"ushort", b"v.raw") + b"endian: little\nencoding: raw\n"
    b"\0" + samples("<H", U16))
put("nhdr", "f32_be_raw_skip.nhdr", nhdr % (b"float", b"./v.raw") + b"endian: big\nencoding: raw\n"
    b"byte skip: 3\n\0abc" + samples(">f", F32))
put("nhdr", "u16_be_gzip.nhdr", nhdr % (b"uint16", b"v.raw.gz") + b"endian: big\nencoding: gzip\n"
    b"\0" + gz(samples(">H", U16)))
put("nhdr", "ascii.nhdr", nhdr % (b"ushort", b"v.txt") + b"encoding: ascii\nline skip: 1\n"
    b"\0# a comment line\n" + TEXT)
put("nhdr", "missing.nhdr", nhdr % (b"uchar", b"missing.raw") + b"encoding: raw\n\0" + bytes(8))

# ---- MetaImage (.mha, LOCAL) ----------------------------------------------------------------
mha = (b"ObjectType = Image\nNDims = 3\nDimSize = 2 2 2\nElementType = %s\n"
       b"ElementSpacing = 1 2 3\nOffset = 4 5 6\n")
put("mha", "u16_le.mha", mha % b"MET_USHORT" + b"BinaryDataByteOrderMSB = False\n"
    b"ElementDataFile = LOCAL\n" + samples("<H", U16))
put("mha", "f32_be.mha", mha % b"MET_FLOAT" + b"ElementByteOrderMSB = True\n"
    b"TransformMatrix = 1 0 0 0 1 0 0 0 1\nElementDataFile = LOCAL\n" + samples(">f", F32))
z = zlib.compress(samples("<H", U16), 9)
put("mha", "u16_zlib_size.mha", mha % b"MET_USHORT" + b"CompressedData = True\n"
    b"CompressedDataSize = %d\nElementDataFile = LOCAL\n" % len(z) + z)
put("mha", "u8_gzip.mha", mha % b"MET_UCHAR" + b"CompressedData = True\nElementDataFile = LOCAL\n"
    + gz(bytes(range(8))))

# ---- MetaImage (.mhd + data file): header, NUL, data file -----------------------------------
mhd = b"NDims = 3\nDimSize = 2 2 2\nElementType = %s\n"
put("mhd", "u16_le.mhd", mhd % b"MET_USHORT" + b"ElementDataFile = v.raw\n\0" + samples("<H", U16))
put("mhd", "i32_be_headersize.mhd", mhd % b"MET_INT" + b"BinaryDataByteOrderMSB = True\n"
    b"HeaderSize = 5\nElementDataFile = v.raw\n\0hello" + samples(">i", [1, -2, 3, -4, 5, -6, 7, -8]))
put("mhd", "f64_end.mhd", mhd % b"MET_DOUBLE" + b"HeaderSize = -1\nElementDataFile = v.raw\n\0xyz"
    + samples("<d", F32))
put("mhd", "u8_zlib.mhd", mhd % b"MET_UCHAR" + b"CompressedData = True\nElementDataFile = v.zraw\n\0"
    + zlib.compress(bytes(range(8))))
put("mhd", "missing.mhd", mhd % b"MET_UCHAR" + b"ElementDataFile = missing.raw\n\0")

# ---- VTK legacy -----------------------------------------------------------------------------
vtk = (b"# vtk DataFile Version 3.0\ntitle\n%s\nDATASET STRUCTURED_POINTS\nDIMENSIONS 2 2 2\n"
       b"SPACING 1 2 3\nORIGIN 4 5 6\nPOINT_DATA 8\nSCALARS s %s 1\n")
put("vtk", "u16_binary.vtk", vtk % (b"BINARY", b"unsigned_short") + b"LOOKUP_TABLE default\n"
    + samples(">H", U16) + b"\n")
put("vtk", "f32_binary.vtk", vtk % (b"BINARY", b"float") + samples(">f", F32)
    + b"\nVECTORS v float\n")
put("vtk", "u16_ascii.vtk", vtk % (b"ASCII", b"unsigned_short") + b"LOOKUP_TABLE default\n" + TEXT)
put("vtk", "f64_ascii_aspect.vtk", vtk.replace(b"SPACING", b"ASPECT_RATIO") % (b"ASCII", b"double")
    + b"0 1.5 -2.25 3 100 -0.5 7 8")

# ---- raw: "X Y Z TYPE ENDIAN HEADER_BYTES [SX SY SZ]" line, then the file ---------------------
put("raw", "u16_le.raw", b"2 2 2 uint16 little 0\n" + samples("<H", U16))
put("raw", "f32_be_header.raw", b"2 2 2 float big 4 1 2 3\n" + b"HEAD" + samples(">f", F32))
put("raw", "i8_char_name.raw", b"2 2 2 char little 0\n" + bytes(8))
put("raw", "f64_le.raw", b"2 2 2 float64 little 0 0.5 0.5 0.5\n" + samples("<d", F32))

# ---- PLY ------------------------------------------------------------------------------------
tet_v = [(0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1)]
tet_f = [(0, 2, 1), (0, 1, 3), (0, 3, 2), (1, 2, 3)]


def ply_header(fmt, normals=False, extra=b""):
    h = b"ply\nformat %s 1.0\ncomment tiny\nelement vertex 4\n" % fmt
    h += b"property float x\nproperty float y\nproperty float z\n"
    if normals:
        h += b"property float nx\nproperty float ny\nproperty float nz\n"
    h += extra + b"element face 4\nproperty list uchar int vertex_indices\nend_header\n"
    return h


ascii_body = b"".join(b"%d %d %d\n" % v for v in tet_v) + b"".join(b"3 %d %d %d\n" % f for f in tet_f)
put("ply", "tet_ascii.ply", ply_header(b"ascii") + ascii_body)
for order, name in ((b"<", b"binary_little_endian"), (b">", b"binary_big_endian")):
    o = order.decode()
    body = b"".join(struct.pack(o + "3f", *v) for v in tet_v)
    body += b"".join(struct.pack(o + "B3i", 3, *f) for f in tet_f)
    put("ply", "tet_%s.ply" % name.decode(), ply_header(name) + body)
    nbody = b"".join(struct.pack(o + "6f", *v, 0, 0, 1) for v in tet_v)
    nbody += b"".join(struct.pack(o + "B3i", 3, *f) for f in tet_f)
    put("ply", "tet_normals_%s.ply" % name.decode(), ply_header(name, True) + nbody)
quad = (b"ply\nformat binary_little_endian 1.0\nelement vertex 4\nproperty double x\n"
        b"property double y\nproperty double z\nproperty uchar red\nelement face 1\n"
        b"property list ushort uint vertex_index\nproperty list uchar float extra\n"
        b"element edge 0\nproperty int vertex1\nend_header\n")
quad += b"".join(struct.pack("<3dB", *v, 7) for v in tet_v) + struct.pack("<H4IBf", 4, 0, 1, 2, 3, 1, 0.5)
put("ply", "quad_doubles_skip.ply", quad)

# ---- OBJ ------------------------------------------------------------------------------------
obj = b"# tet\n" + b"".join(b"v %d %d %d\n" % v for v in tet_v)
put("obj", "tet.obj", obj + b"".join(b"f %d %d %d\n" % (a + 1, b + 1, c + 1) for a, b, c in tet_f))
put("obj", "tet_normals.obj", obj + b"vn 0 0 1\nvn 0 1 0\nvn 1 0 0\nvn 0 0 -1\n"
    + b"".join(b"f %d//%d %d//%d %d//%d\n" % (a + 1, a + 1, b + 1, b + 1, c + 1, c + 1)
               for a, b, c in tet_f))
put("obj", "quad_relative.obj", b"o q\ng g\nv 0 0 0\nv 1 0 0 1\nv 1 1 0\nv 0 1 0\nvt 0 0\n"
    b"usemtl m\ns off\nf -4/1 -3/1 -2/1 -1/1\nl 1 2\n")

# ---- STL ------------------------------------------------------------------------------------
tris = [[tet_v[i] for i in f] for f in tet_f]
binary = b"binary stl".ljust(80, b" ") + struct.pack("<I", len(tris))
binary += b"".join(struct.pack("<12fH", 0, 0, 0, *t[0], *t[1], *t[2], 0) for t in tris)
put("stl", "tet_binary.stl", binary)
solid = b"solid tet\n"
for t in tris:
    solid += b" facet normal 0 0 0\n  outer loop\n"
    solid += b"".join(b"   vertex %d %d %d\n" % v for v in t)
    solid += b"  endloop\n endfacet\n"
put("stl", "tet_ascii.stl", solid + b"endsolid tet\n")
put("stl", "two_solids_upper.stl", solid.upper() + b"ENDSOLID\n" + solid + b"endsolid\n")

# ---- OFF ------------------------------------------------------------------------------------
off_v = b"".join(b"%d %d %d\n" % v for v in tet_v)
off_f = b"".join(b"3 %d %d %d\n" % f for f in tet_f)
put("off", "tet.off", b"OFF\n4 4 6\n" + off_v + off_f)
put("off", "tet_noff.off", b"NOFF 4 4 0\n" + b"".join(b"%d %d %d 0 0 1\n" % v for v in tet_v) + off_f)
put("off", "quad_coff.off", b"# c\nCOFF\n4 1 0\n" + b"".join(b"%d %d %d 1 0 0 1\n" % v for v in tet_v)
    + b"4 0 1 2 3 255 0 0\n")
