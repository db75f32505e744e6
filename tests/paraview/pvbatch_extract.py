"""Run by pvbatch (test_pvbatch.py): loads the cmc33 plugin, reads the volume with ParaView's own
reader, applies "CMC33 Isosurface" and prints one JSON line with the mesh's counts and the field
data's topology. Arguments: VOLUME ISOVALUE."""

import json
import sys

from paraview import servermanager, simple

import cmc33.vtk

volume, iso = sys.argv[1], float(sys.argv[2])
cmc33.vtk.load_paraview_plugin()  # the filter joins paraview.simple
reader = simple.OpenDataFile(volume)
if reader is None:
    sys.exit(f"{volume}: ParaView has no reader for this file")
reader.UpdatePipeline()
array = reader.PointData.keys()[0]
surface = simple.CMC33Isosurface(Input=reader, ContourBy=["POINTS", array], Isosurfaces=[iso],
                                 ComputeNormals=0, Threads=2)
mesh = servermanager.Fetch(surface)
fields = mesh.GetFieldData()
print(json.dumps({
    "vertices": mesh.GetNumberOfPoints(),
    "triangles": mesh.GetNumberOfCells(),
    "euler": fields.GetArray("cmc33_euler").GetValue(0),
    "betti": [int(v) for v in fields.GetArray("cmc33_betti").GetTuple3(0)],
    "embedded": bool(fields.GetArray("cmc33_embedded").GetValue(0)),
    "manifold": bool(fields.GetArray("cmc33_manifold").GetValue(0)),
    "isovalues": [fields.GetArray("cmc33_isovalues").GetValue(0)],
    "bounds": list(mesh.GetBounds()),
}))
