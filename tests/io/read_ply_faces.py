#!/usr/bin/python3
"""A triangle PLY with face properties read independently of cmc33, written as JSON for
tests/io/test_mesh_ply_faces.cpp to compare with what it wrote:
{"points": [[x, y, z], ...], "triangles": [[a, b, c], ...], "cell_data": {NAME: [v, ...]},
 "dtypes": {NAME: numpy dtype}, "meshio": true if meshio read it too}.

The header and records are parsed here with numpy (a structured dtype per record in binary, the
tokens in ASCII). An ASCII file is also read by meshio, which must find the same values; meshio
5.0's binary PLY reader takes one value per face property and then fails, so binary files are
numpy's alone. Floats go out as Python floats, which hold every float32 exactly.

Usage: read_ply_faces.py IN.ply OUT.json
Exit 77 (the test skips) when numpy is not installed (python3-numpy); meshio (python3-meshio)
missing only leaves "meshio" false.
"""

import json
import math
import sys

try:
    import numpy as np
except ImportError as e:
    print(f"skipped: {e} (python3-numpy)")
    sys.exit(77)

NUMPY = {"char": "i1", "uchar": "u1", "short": "i2", "ushort": "u2", "int": "i4", "uint": "u4",
         "float": "f4", "double": "f8"}


def parse(path):
    with open(path, "rb") as f:
        data = f.read()
    head, body = data.split(b"end_header\n", 1)
    lines = head.decode("ascii").split("\n")
    assert lines[0] == "ply", lines[0]
    encoding = None
    elements = []  # [name, count, [(type or ("list", count type, item type), name)]]
    for line in lines[1:]:
        w = line.split()
        if not w or w[0] == "comment":
            continue
        if w[0] == "format":
            encoding = w[1]
        elif w[0] == "element":
            elements.append([w[1], int(w[2]), []])
        elif w[0] == "property" and w[1] == "list":
            elements[-1][2].append((("list", w[2], w[3]), w[4]))
        elif w[0] == "property":
            elements[-1][2].append((w[1], w[2]))
    assert [e[0] for e in elements] == ["vertex", "face"], elements
    (_, nv, vprops), (_, nf, fprops) = elements
    assert fprops[0] == (("list", "uchar", "uint"), "vertex_indices"), fprops[0]
    scalars = fprops[1:]
    if encoding == "binary_little_endian":
        vtype = np.dtype([(n, "<" + NUMPY[t]) for t, n in vprops])
        ftype = np.dtype([("n", "u1"), ("idx", "<u4", (3,))] + [(n, "<" + NUMPY[t]) for t, n in scalars])
        assert len(body) == nv * vtype.itemsize + nf * ftype.itemsize, "the data is not as long as the header says"
        v = np.frombuffer(body, vtype, nv)
        f = np.frombuffer(body, ftype, nf, offset=nv * vtype.itemsize)
        assert (f["n"] == 3).all()
        points = np.stack([v["x"], v["y"], v["z"]], axis=1)
        return points, f["idx"], {n: f[n] for _, n in scalars}
    assert encoding == "ascii", encoding
    rows = body.decode("ascii").split("\n")
    assert rows[-1] == "" and len(rows) == nv + nf + 1, "one line per record"
    points = np.array([[np.float32(x) for x in r.split()[:3]] for r in rows[:nv]], dtype=np.float32).reshape(nv, 3)
    faces = [r.split() for r in rows[nv:nv + nf]]
    assert all(len(r) == 4 + len(scalars) and r[0] == "3" for r in faces), "3 indices and the scalars on each line"
    triangles = np.array([[int(x) for x in r[1:4]] for r in faces], dtype=np.int64).reshape(nf, 3)
    cell_data = {}
    for k, (t, n) in enumerate(scalars):
        values = [r[4 + k] for r in faces]
        if t in ("float", "double"):
            cell_data[n] = np.array([float(x) for x in values], dtype=NUMPY[t])
        else:
            ints = [int(x) for x in values]
            info = np.iinfo(np.dtype(NUMPY[t]))
            assert all(info.min <= x <= info.max for x in ints), f"{n}: a value outside {t}"
            cell_data[n] = np.array(ints, dtype=NUMPY[t])
    return points, triangles, cell_data


def number(v):
    return v if not (isinstance(v, float) and not math.isfinite(v)) else repr(v)  # JSON has no nan, inf


def main():
    points, triangles, cell_data = parse(sys.argv[1])
    by_meshio = False
    if b"format ascii" in open(sys.argv[1], "rb").read(64):
        try:
            import meshio
        except ImportError:
            meshio = None
        if meshio is not None:
            m = meshio.read(sys.argv[1], file_format="ply")
            assert [c.type for c in m.cells] == ["triangle"], m.cells
            assert np.array_equal(m.points, points), "meshio's points differ"
            assert np.array_equal(m.cells[0].data, triangles), "meshio's triangles differ"
            assert sorted(m.cell_data) == sorted(cell_data), (sorted(m.cell_data), sorted(cell_data))
            for name, values in cell_data.items():
                assert np.array_equal(m.cell_data[name][0], values, equal_nan=True), f"meshio's {name} differs"
            by_meshio = True
    out = {
        "points": points.astype(np.float64).tolist(),
        "triangles": np.asarray(triangles).tolist(),
        "cell_data": {n: [number(x) for x in v.tolist()] for n, v in cell_data.items()},
        "dtypes": {n: str(v.dtype) for n, v in cell_data.items()},
        "meshio": by_meshio,
    }
    with open(sys.argv[2], "w") as f:
        json.dump(out, f)


if __name__ == "__main__":
    main()
