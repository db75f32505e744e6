"""cmc33: topologically correct, manifold, embedded isosurfaces (Marching Cubes 33 as corrected by
Custodio, Etiene, Pesco and Silva 2013), from numpy arrays, in place.

Two ways in:

* :func:`marching_cubes` is a drop-in replacement for ``skimage.measure.marching_cubes``: the same
  call and the same four arrays, with cmc33's mesh, many times faster.
* :func:`extract` is the library's own call: a :class:`Mesh` whose ``vertices``, ``triangles`` and
  ``normals`` are numpy arrays over the library's memory, in the volume's world frame.

Beside them: :func:`read_volume`, :func:`write_volume`, :func:`read_mesh`, :func:`write_mesh`,
:func:`mesh_topology`, :func:`field_topology` (the topology the mesh must have),
:func:`mesh_geometry` (embedding checks with exact predicates), :func:`label_surfaces` (every
structure of a segmentation, sharing their interfaces), :func:`analyze_cell` and
:func:`verify` (the stress test). Errors are subclasses of :class:`Error` and of the built-in
exception one expects (ValueError, OSError, MemoryError).

>>> import numpy as np, cmc33
>>> z, y, x = np.mgrid[-1:1:40j, -1:1:40j, -1:1:40j]
>>> verts, faces, normals, values = cmc33.marching_cubes(x**2 + y**2 + z**2, 0.5)
>>> cmc33.mesh_topology((verts, faces)).euler
2
"""

from ._errors import (CancelledError, Error, FileError, FormatError, InternalError, InvalidArgumentError,
                      NonFiniteError, TooLargeError, TruncatedFileError, UnsupportedFormatError)
from ._cmc33 import (CellReport, FaceReport, FieldTopology, InteriorReport, Mesh, MeshGeometry, MeshTopology,
                     MethodReport, VerifyReport, Volume, subcase_names)
from ._api import (METHODS, analyze_cell, extract, field_topology, mesh_geometry, mesh_topology, random_field,
                   read_mesh, read_volume, verify, write_mesh, write_volume)
from ._labels import LabelSurfaces, label_surfaces
from ._skimage import marching_cubes
from ._cmc33 import version as __version__

__all__ = [
    "marching_cubes", "extract", "label_surfaces", "LabelSurfaces", "read_volume", "write_volume", "read_mesh", "write_mesh", "mesh_topology",
    "mesh_geometry", "field_topology", "analyze_cell", "random_field", "verify", "subcase_names", "METHODS",
    "Mesh", "Volume", "MeshTopology", "MeshGeometry", "FieldTopology", "CellReport", "FaceReport",
    "InteriorReport", "MethodReport", "VerifyReport",
    "Error", "InvalidArgumentError", "FileError", "TruncatedFileError", "FormatError", "UnsupportedFormatError",
    "NonFiniteError", "TooLargeError", "CancelledError", "InternalError",
]
