#!/usr/bin/python3
"""Writes the meshes two peers extract, as binary PLY, so that `cmc33 topo` can judge them in space
(coincident vertices, zero-area and intersecting triangles, topology after welding by position).

    peer_meshes.py FILE ISO OUTDIR

Reads FILE (NRRD, as bench/skimage_bench.py reads it) and writes
  OUTDIR/skimage.ply  skimage.measure.marching_cubes(volume, ISO, method='lewiner')
  OUTDIR/vtk-fe.ply   vtkFlyingEdges3D at ISO (through VTK's Python wrapping; skipped without it)
with x, y, z in the volume's index space (spacing 1), as cmc33 extract writes it for spacing 1.
Then run `cmc33 topo OUTDIR/skimage.ply`. Exit codes: 0 written, 1 bad input, 2 usage error.
"""

import os
import struct
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from skimage_bench import read_nrrd  # noqa: E402


def write_ply(path, vertices, triangles):
    """vertices: n x 3 (x, y, z); triangles: m x 3 indices."""
    import numpy as np
    v = np.ascontiguousarray(vertices, dtype="<f4")
    t = np.zeros(len(triangles), dtype=[("n", "u1"), ("i", "<i4", 3)])
    t["n"] = 3
    t["i"] = triangles
    with open(path, "wb") as out:
        out.write(b"ply\nformat binary_little_endian 1.0\nelement vertex %d\n"
                  b"property float x\nproperty float y\nproperty float z\n"
                  b"element face %d\nproperty list uchar int vertex_indices\nend_header\n"
                  % (len(v), len(t)))
        out.write(v.tobytes())
        out.write(t.tobytes())


def main(argv):
    if len(argv) != 4:
        print(__doc__.strip().splitlines()[2].strip(), file=sys.stderr)
        return 2
    path, iso, outdir = argv[1], float(argv[2]), argv[3]
    volume = read_nrrd(path)  # (z, y, x)
    os.makedirs(outdir, exist_ok=True)
    from skimage import measure
    verts, faces, _, _ = measure.marching_cubes(volume, level=iso, method="lewiner")
    write_ply(os.path.join(outdir, "skimage.ply"), verts[:, ::-1], faces)  # (z, y, x) -> (x, y, z)
    try:
        import vtk
        from vtk.util import numpy_support
    except ImportError:
        print("peer_meshes.py: no VTK Python wrapping (Debian python3-vtk9); vtk-fe.ply not written",
              file=sys.stderr)
        return 0
    image = vtk.vtkImageData()
    image.SetDimensions(volume.shape[2], volume.shape[1], volume.shape[0])
    image.GetPointData().SetScalars(numpy_support.numpy_to_vtk(volume.ravel(), deep=1))
    fe = vtk.vtkFlyingEdges3D()
    fe.SetInputData(image)
    fe.SetValue(0, iso)
    fe.Update()
    mesh = fe.GetOutput()
    points = numpy_support.vtk_to_numpy(mesh.GetPoints().GetData())
    cells = numpy_support.vtk_to_numpy(mesh.GetPolys().GetConnectivityArray()).reshape(-1, 3)
    write_ply(os.path.join(outdir, "vtk-fe.ply"), points, cells)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
