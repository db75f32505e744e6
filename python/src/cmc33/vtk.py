"""cmc33 in VTK pipelines: vtkImageData to samples and frame, meshes to vtkPolyData, and
:class:`ExtractFilter`, a ``VTKPythonAlgorithmBase`` (vtkImageData in, vtkPolyData out) that runs
:func:`cmc33.extract` on the image's point scalars.

This module needs VTK's Python bindings (Debian ``python3-vtk9``, or pip's ``vtk``, or ParaView's
own); the rest of the package does not import it.

>>> from cmc33.vtk import ExtractFilter            # doctest: +SKIP
>>> f = ExtractFilter(); f.SetInputData(image); f.SetIsovalue(80.5); f.Update()
>>> f.GetOutput().GetNumberOfCells(), f.GetOutput().GetFieldData().GetArray("cmc33_euler").GetValue(0)

Frames: a vertex is placed where ``image.GetIndexToPhysicalMatrix()`` maps its continuous index
(i, j, k): origin + direction @ (spacing * (i, j, k)), the image's Extent, Spacing (negative too)
and DirectionMatrix included. The samples are read in place (``numpy_support.vtk_to_numpy`` is a
view over VTK's memory); the output's points, triangles and normals are copied once into VTK
arrays (VTK's cell arrays hold 64-bit ids where the mesh holds 32-bit ones).
"""

from __future__ import annotations

import os
from typing import Any, Dict, Optional, Sequence, Tuple, Union

import numpy as np

try:  # vtkmodules is VTK's own package, in ParaView's Python as well
    from vtkmodules.util import numpy_support
    from vtkmodules.util.vtkAlgorithm import VTKPythonAlgorithmBase
    from vtkmodules.vtkCommonCore import vtkDoubleArray, vtkIntArray, vtkOutputWindow, vtkPoints, vtkStringArray
    from vtkmodules.vtkCommonDataModel import vtkCellArray, vtkDataObject, vtkImageData, vtkPolyData
except ImportError as e:  # pragma: no cover - depends on the environment
    raise ImportError(f"cmc33.vtk needs VTK's Python bindings (Debian: python3-vtk9; pip: vtk): {e}") from e

from . import _api
from ._api import METHODS  # noqa: F401 - the plugin's Method choices
from ._arrays import thread_count
from ._cmc33 import Mesh, Volume
from ._cmc33 import version as __version__  # noqa: F401 - the plugin's version
from ._errors import Error

__all__ = ["ExtractFilter", "image_to_samples", "samples_to_image", "mesh_to_polydata", "topology_arrays",
           "PARAVIEW_PLUGIN", "load_paraview_plugin"]

#: The ParaView plugin file (a Python plugin over ExtractFilter): Tools > Manage Plugins > Load New.
PARAVIEW_PLUGIN = os.path.join(os.path.dirname(os.path.abspath(__file__)), "paraview_plugin.py")

#: vtkDataObject.FIELD_ASSOCIATION_POINTS: SetInputArrayToProcess's association for point data.
_POINTS = 0


def _frame(image: Any) -> Dict[str, Any]:
    """spacing, origin and direction (x, y, z order) placing sample (i, j, k) of the extent's first
    index where VTK's index-to-physical matrix puts index (i0 + i, j0 + j, k0 + k)."""
    spacing = np.array(image.GetSpacing(), dtype=float)
    direction = np.array([[image.GetDirectionMatrix().GetElement(r, c) for c in range(3)] for r in range(3)])
    first = np.array(image.GetExtent()[0::2], dtype=float)
    origin = np.array(image.GetOrigin(), dtype=float) + direction @ (spacing * first)
    # the library takes positive steps: a negative spacing is a mirrored axis of the direction
    signs = np.where(spacing < 0, -1.0, 1.0)
    return {"spacing": tuple(np.abs(spacing)), "origin": tuple(origin), "direction": direction * signs}


def image_to_samples(image: Any, array: Optional[str] = None) -> Tuple[np.ndarray, Dict[str, Any]]:
    """``(samples, frame)`` of a vtkImageData: ``samples`` a (nz, ny, nx) numpy view over the
    point array ``array`` (default: the active scalars), no copy; ``frame`` the keywords
    ``spacing``, ``origin`` and ``direction`` of :func:`cmc33.extract`, so that
    ``cmc33.extract(samples, iso, **frame)`` places vertices in the image's physical frame.
    ValueError: no such array, not one component, or an image that is not 3D."""
    data = image.GetPointData()
    values = data.GetScalars() if array is None else data.GetArray(array)
    if values is None:
        names = [data.GetArrayName(i) for i in range(data.GetNumberOfArrays())]
        what = "no active point scalars" if array is None else f"no point array {array!r}"
        raise ValueError(f"the vtkImageData has {what}; its point arrays: {names or 'none'}")
    name = values.GetName() or "scalars"
    if values.GetNumberOfComponents() != 1:
        raise ValueError(f"point array {name!r} has {values.GetNumberOfComponents()} components; expected 1 "
                         "(vtkImageExtractComponents or vtkArrayCalculator make one)")
    nx, ny, nz = image.GetDimensions()
    if min(nx, ny, nz) < 2:
        raise ValueError(f"the vtkImageData has dimensions {nx} x {ny} x {nz}; expected at least 2 samples on each axis")
    if values.GetNumberOfTuples() != nx * ny * nz:
        raise ValueError(f"point array {name!r} has {values.GetNumberOfTuples()} values; expected {nx * ny * nz} "
                         f"({nx} x {ny} x {nz})")
    try:
        flat = numpy_support.vtk_to_numpy(values)  # a view of VTK's memory
    except (AssertionError, KeyError, TypeError, ValueError) as e:  # bit or string arrays
        raise ValueError(f"point array {name!r} of type {values.GetDataTypeAsString()} cannot be read as "
                         f"numbers ({e}); expected integers or floating-point numbers") from None
    return flat.reshape(nz, ny, nx), _frame(image)  # x fastest in VTK, as in the library


def samples_to_image(volume: Union[Volume, Any], *, spacing: Optional[Sequence[float]] = None,
                     origin: Optional[Sequence[float]] = None, direction: Any = None,
                     name: str = "scalars") -> Any:
    """A vtkImageData of a cmc33.Volume or a (nz, ny, nx) array, its frame as in
    :func:`cmc33.extract` (a Volume's own unless given). The samples are copied into a VTK array
    named ``name``, the active scalars."""
    if isinstance(volume, Volume):
        samples = volume.samples
        spacing = volume.spacing if spacing is None else spacing
        origin = volume.origin if origin is None else origin
        direction = volume.direction if direction is None else direction
    else:
        samples = np.asarray(volume)
    if samples.ndim != 3:
        raise ValueError(f"volume has {samples.ndim} dimensions (shape {samples.shape}); expected a 3D array")
    nz, ny, nx = samples.shape
    image = vtkImageData()
    image.SetDimensions(nx, ny, nz)
    image.SetSpacing(*(1.0, 1.0, 1.0) if spacing is None else (float(s) for s in spacing))
    image.SetOrigin(*(0.0, 0.0, 0.0) if origin is None else (float(s) for s in origin))
    if direction is not None:
        image.SetDirectionMatrix(*(float(v) for v in np.asarray(direction, dtype=float).reshape(9)))
    values = numpy_support.numpy_to_vtk(np.ascontiguousarray(samples).reshape(-1), deep=1)
    values.SetName(name)
    image.GetPointData().SetScalars(values)
    return image


def mesh_to_polydata(mesh: Any, *, scalars: Optional[np.ndarray] = None, scalars_name: str = "isovalue") -> Any:
    """A vtkPolyData of a cmc33.Mesh (or (vertices, triangles[, normals]) arrays): points,
    triangles, the normals as the point data's normals ("Normals") when the mesh has them, and
    ``scalars`` (one value per vertex) as the point data's scalars named ``scalars_name``.
    Copied into VTK arrays."""
    mesh = _api.as_mesh(mesh)
    vertices = np.ascontiguousarray(mesh.vertices)
    triangles = np.asarray(mesh.triangles)
    poly = vtkPolyData()
    points = vtkPoints()
    points.SetData(numpy_support.numpy_to_vtk(vertices, deep=1))
    poly.SetPoints(points)
    connectivity = triangles.astype(np.int64).reshape(-1)
    offsets = np.arange(0, connectivity.size + 1, 3, dtype=np.int64)
    cells = vtkCellArray()
    cells.SetData(numpy_support.numpy_to_vtkIdTypeArray(offsets, deep=1),
                  numpy_support.numpy_to_vtkIdTypeArray(connectivity, deep=1))
    poly.SetPolys(cells)
    if mesh.normals is not None:
        normals = numpy_support.numpy_to_vtk(np.ascontiguousarray(mesh.normals), deep=1)
        normals.SetName("Normals")
        poly.GetPointData().SetNormals(normals)
    if scalars is not None:
        if len(scalars) != len(vertices):
            raise ValueError(f"scalars has {len(scalars)} values; expected one per vertex ({len(vertices)})")
        values = numpy_support.numpy_to_vtk(np.ascontiguousarray(scalars), deep=1)
        values.SetName(scalars_name)
        poly.GetPointData().SetScalars(values)
    return poly


def _int_array(name: str, rows: Sequence[Sequence[int]], components: int) -> Any:
    array = vtkIntArray()
    array.SetName(name)
    array.SetNumberOfComponents(components)
    for row in rows:
        array.InsertNextTypedTuple(tuple(int(v) for v in row))
    return array


def topology_arrays(meshes: Sequence[Any], *, embedding: bool = True, threads: int = 0) -> list:
    """Field-data arrays stating each mesh's topology and embedding verdict, one tuple per mesh:
    ``cmc33_euler``, ``cmc33_betti`` (b0, b1, b2 as ``cmc33 extract --json`` prints them:
    components, b1, closed components), ``cmc33_boundary_loops``, ``cmc33_nonmanifold_edges``,
    ``cmc33_nonmanifold_vertices``, ``cmc33_manifold`` (1 when there is no non-manifold edge or
    vertex) and, with ``embedding``, ``cmc33_embedded`` (1 when exact predicates find no
    coincident vertices, zero-area triangles or intersecting pairs: cmc33.mesh_geometry)."""
    tops = [_api.mesh_topology(m) for m in meshes]
    arrays = [
        _int_array("cmc33_euler", [(t.euler,) for t in tops], 1),
        _int_array("cmc33_betti", [(t.components, t.b1, t.closed_components) for t in tops], 3),
        _int_array("cmc33_boundary_loops", [(t.boundary_loops,) for t in tops], 1),
        _int_array("cmc33_nonmanifold_edges", [(t.nonmanifold_edges,) for t in tops], 1),
        _int_array("cmc33_nonmanifold_vertices", [(t.nonmanifold_vertices,) for t in tops], 1),
        _int_array("cmc33_manifold", [(int(t.nonmanifold_edges == 0 and t.nonmanifold_vertices == 0),)
                                      for t in tops], 1),
    ]
    arrays[1].SetComponentName(0, "b0")
    arrays[1].SetComponentName(1, "b1")
    arrays[1].SetComponentName(2, "b2")
    if embedding:
        arrays.append(_int_array("cmc33_embedded",
                                 [(int(_api.mesh_geometry(m, threads=threads, examples=0).embedded),)
                                  for m in meshes], 1))
    return arrays


class ExtractFilter(VTKPythonAlgorithmBase):
    """cmc33's isosurface as a VTK filter: vtkImageData in, vtkPolyData out.

    The mesh of each isovalue is :func:`cmc33.extract` on the image's point scalars (or the point
    array chosen by ``SetInputArrayToProcess(0, 0, 0, 0, name)``), placed in the image's physical
    frame (Origin, Spacing, Extent and DirectionMatrix). Several isovalues give one mesh each,
    appended in order; the point data's scalars, named as the input array, hold each vertex's
    isovalue (as vtkContourFilter's do). With normals on, "Normals" are unit per-vertex normals
    from the field's gradient, pointing from higher to lower values.

    With topology on (the default), the output's field data states the guarantee, one tuple per
    isovalue: ``cmc33_isovalues``, ``cmc33_euler``, ``cmc33_betti``, ``cmc33_manifold``, ... and
    ``cmc33_embedded`` (see :func:`topology_arrays`), and ``cmc33_method`` names the method.

    Errors of the input (no scalars, several components, NaN samples) fail the request as VTK's
    filters do: a one-line message on VTK's output window (ParaView's Output Messages), an empty
    output, and the message in GetLastError(). Bad options raise at once from the Set methods.
    """

    def __init__(self) -> None:
        VTKPythonAlgorithmBase.__init__(self, nInputPorts=1, inputType="vtkImageData", nOutputPorts=1,
                                        outputType="vtkPolyData")
        self._isovalues: list = [0.0]
        self._method = "cmc33"
        self._normals = False
        self._topology = True
        self._embedding = True
        self._threads = 0
        self._error: Optional[str] = None

    def SetInputData(self, image: Any) -> None:
        """The input image, without a pipeline (as vtkImageAlgorithm's SetInputData)."""
        self.SetInputDataObject(0, image)

    def GetOutput(self) -> Any:
        """The output vtkPolyData (after Update())."""
        return self.GetOutputDataObject(0)

    # --- options (VTK's Set/Get style, which ParaView's properties call) ------------------------
    def SetIsovalue(self, value: float) -> None:
        """One isovalue (replaces the list)."""
        self.SetIsovalues([value])

    def SetIsovalues(self, values: Sequence[float]) -> None:
        """The isovalues, one mesh each, in order (none: an empty output)."""
        values = [float(v) for v in values]
        if values != self._isovalues:
            self._isovalues = values
            self.Modified()

    def GetIsovalues(self) -> Tuple[float, ...]:
        return tuple(self._isovalues)

    def SetNumberOfIsovalues(self, n: int) -> None:
        """Resizes the list (new entries 0), as ParaView's repeated value properties do."""
        n = int(n)
        if n < 0:
            raise ValueError(f"number of isovalues {n}; expected 0 or more")
        values = (self._isovalues + [0.0] * n)[:n]
        if values != self._isovalues:
            self._isovalues = values
            self.Modified()

    def SetIsovalueAt(self, index: int, value: float) -> None:
        """Isovalue ``index`` (the list grows as needed)."""
        index = int(index)
        if index < 0:
            raise ValueError(f"isovalue index {index}; expected 0 or more")
        values = list(self._isovalues) + [0.0] * max(0, index + 1 - len(self._isovalues))
        values[index] = float(value)
        if values != self._isovalues:
            self._isovalues = values
            self.Modified()

    def SetMethod(self, method: Union[str, int]) -> None:
        """'cmc33' (default, topologically correct), 'mc33-lewiner' or 'mc', or an index into
        cmc33.METHODS."""
        if isinstance(method, (int, np.integer)) and not isinstance(method, bool):
            if not 0 <= int(method) < len(_api.METHODS):
                raise ValueError(f"method index {method}; expected 0 to {len(_api.METHODS) - 1} ({_api.METHODS})")
            method = _api.METHODS[int(method)]
        name = _api._method(str(method))
        if name != self._method:
            self._method = name
            self.Modified()

    def GetMethod(self) -> str:
        return self._method

    def _set(self, attr: str, value: Any) -> None:
        if getattr(self, attr) != value:
            setattr(self, attr, value)
            self.Modified()

    def SetComputeNormals(self, on: Any) -> None:
        self._set("_normals", bool(on))

    def GetComputeNormals(self) -> bool:
        return self._normals

    def SetComputeTopology(self, on: Any) -> None:
        """State the meshes' topology in the field data (default on)."""
        self._set("_topology", bool(on))

    def GetComputeTopology(self) -> bool:
        return self._topology

    def SetCheckEmbedding(self, on: Any) -> None:
        """With topology on, also check the meshes' embedding with exact predicates (default on)."""
        self._set("_embedding", bool(on))

    def GetCheckEmbedding(self) -> bool:
        return self._embedding

    def SetThreads(self, threads: int) -> None:
        """Worker threads, 0 (default) for every core; the mesh is the same for every count."""
        self._set("_threads", thread_count(threads))

    def GetThreads(self) -> int:
        return self._threads

    # --- the pipeline ---------------------------------------------------------------------------
    def _array_name(self, image: Any) -> Optional[str]:
        """The point array SetInputArrayToProcess chose, or None for the active scalars."""
        info = self.GetInputArrayInformation(0)
        if info is None or not info.Has(vtkDataObject.FIELD_NAME()):
            return None
        if info.Has(vtkDataObject.FIELD_ASSOCIATION()) and info.Get(vtkDataObject.FIELD_ASSOCIATION()) != _POINTS:
            raise ValueError(f"input array {info.Get(vtkDataObject.FIELD_NAME())!r} is not a point array; "
                             "cmc33 extracts from point (sample) values")
        return info.Get(vtkDataObject.FIELD_NAME())

    def GetLastError(self) -> Optional[str]:
        """The one-line message of the last Update()'s error, None when it succeeded."""
        return self._error

    def RequestData(self, request: Any, inInfo: Any, outInfo: Any) -> int:
        # VTK does not pass a filter's exception to Update()'s caller: report it in one line as
        # VTK's own filters do, keep it for GetLastError(), and fail the request
        self._error = None
        try:
            return self._request_data(inInfo, outInfo)
        except (Error, ValueError, MemoryError) as e:
            self._error = f"cmc33.vtk.ExtractFilter: {e}"
            vtkOutputWindow.GetInstance().DisplayErrorText(self._error + "\n")
            vtkPolyData.GetData(outInfo).Initialize()
            return 0

    def _request_data(self, inInfo: Any, outInfo: Any) -> int:
        image = vtkImageData.GetData(inInfo[0])
        output = vtkPolyData.GetData(outInfo)
        chosen = self._array_name(image)
        samples, frame = image_to_samples(image, chosen)
        name = chosen or image.GetPointData().GetScalars().GetName() or "isovalue"
        count = len(self._isovalues)

        meshes = []
        for n, iso in enumerate(self._isovalues):
            def progress(fraction: float, n: int = n) -> bool:
                self.UpdateProgress((n + fraction) / count)
                return not self.GetAbortExecute()
            meshes.append(_api.extract(samples, iso, **frame, method=self._method, normals=self._normals,
                                       threads=self._threads, progress=progress))

        if count == 0:  # as vtkContourFilter without values: an empty output
            whole = Mesh(np.zeros((0, 3), np.float32), np.zeros((0, 3), np.uint32))
        else:
            whole = meshes[0] if count == 1 else _append(meshes, self._normals)
        values = np.repeat(np.array(self._isovalues, dtype=np.float64), [m.vertex_count for m in meshes])
        output.ShallowCopy(mesh_to_polydata(whole, scalars=values, scalars_name=name))

        fields = output.GetFieldData()
        isovalues = vtkDoubleArray()
        isovalues.SetName("cmc33_isovalues")
        for iso in self._isovalues:
            isovalues.InsertNextValue(iso)
        fields.AddArray(isovalues)
        method = vtkStringArray()
        method.SetName("cmc33_method")
        method.InsertNextValue(self._method)
        fields.AddArray(method)
        if self._topology:
            for array in topology_arrays(meshes, embedding=self._embedding, threads=self._threads):
                fields.AddArray(array)
        return 1


def load_paraview_plugin(ns: Optional[dict] = None) -> None:
    """Loads the ParaView plugin (PARAVIEW_PLUGIN) in pvpython or pvbatch; the filter is then
    ``CMC33Isosurface(Input=..., Isovalues=[...])`` in ``ns`` (pass ``globals()`` after
    ``from paraview.simple import *``) and in paraview.simple. On Python 3.11 and later it first
    gives ``inspect`` back the ``getargspec`` that ParaView 5.11's plugin loader imports."""
    import inspect
    if not hasattr(inspect, "getargspec"):
        inspect.getargspec = inspect.getfullargspec  # type: ignore[attr-defined]
    from paraview import simple
    simple.LoadPlugin(PARAVIEW_PLUGIN, remote=False, ns=ns)


def _append(meshes: Sequence[Mesh], normals: bool) -> Mesh:
    """The meshes as one (their vertices and triangles in order)."""
    offsets = np.cumsum([0] + [m.vertex_count for m in meshes[:-1]])
    vertices = np.concatenate([m.vertices for m in meshes])
    triangles = np.concatenate([m.triangles.astype(np.int64) + o for m, o in zip(meshes, offsets)])
    if triangles.size and triangles.max() > np.iinfo(np.uint32).max:
        raise ValueError(f"the appended meshes have {len(vertices)} vertices; at most 2^32 - 1 can be indexed")
    return Mesh(vertices, triangles.astype(np.uint32), np.concatenate([m.normals for m in meshes]) if normals else None)
