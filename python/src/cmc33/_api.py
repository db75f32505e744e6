"""The native API: the C++ library's functions with Python arguments."""

from __future__ import annotations

import os
import re
from typing import Any, Callable, Optional, Sequence, Tuple, Union

import numpy as np

from . import _cmc33
from ._arrays import IDENTITY, as_samples, mat3, method_name, raise_non_finite, thread_count, vec3
from ._cmc33 import (CellReport, FieldTopology, Mesh, MeshGeometry, MeshTopology, VerifyReport,
                     Volume)
from ._errors import Error, InvalidArgumentError, NonFiniteError

PathLike = Union[str, "os.PathLike[str]"]
#: A Mesh, or arrays (vertices, triangles[, normals, ...]) such as marching_cubes returns.
MeshLike = Union[Mesh, Sequence[Any]]

METHODS: Tuple[str, ...] = tuple(_cmc33.method_names())
#: A command-line option in a reader's message ("--frame N", "--space"), as read_volume's argument.
_OPTION = re.compile(r"--(frame|array|series|spacing|origin|space)\b(?: (N|NAME|UID))?")


def _method(method: str) -> str:
    return method_name(method, METHODS)


def as_mesh(mesh: MeshLike) -> Mesh:
    """``mesh`` itself if it is a Mesh; else a Mesh copied from (vertices, triangles[, normals])
    (the first two or three items, so marching_cubes' 4-tuple works too)."""
    if isinstance(mesh, Mesh):
        return mesh
    try:
        items = list(mesh)
    except TypeError:
        raise ValueError(f"expected a cmc33.Mesh or (vertices, triangles), not {type(mesh).__name__}") from None
    if len(items) < 2:
        raise ValueError(f"expected a cmc33.Mesh or (vertices, triangles); got {len(items)} items")
    triangles = np.asarray(items[1])
    if triangles.dtype.kind not in "iu":
        raise ValueError(f"triangles have type {triangles.dtype}; expected integers")
    normals = items[2] if len(items) > 2 and items[2] is not None else None
    return Mesh(np.asarray(items[0]), triangles, normals)


def extract(volume: Union[Volume, Any], iso: float, *, spacing: Optional[Sequence[float]] = None,
            origin: Optional[Sequence[float]] = None, direction: Any = None, method: str = "cmc33",
            normals: bool = False, threads: int = 0,
            progress: Optional[Callable[[float], Optional[bool]]] = None) -> Mesh:
    """Extracts the isosurface ``f = iso`` of a volume as a Mesh (cmc33::extract).

    The mesh has the topology of the level set of the trilinear interpolant of the samples, is
    manifold and embedded, and is the same byte for byte for every thread count and memory
    layout. A sample equal to ``iso`` counts as above it.

    Parameters
    ----------
    volume : cmc33.Volume or 3D array
        A Volume (from read_volume; its frame is used unless overridden here), or an array of
        shape (nz, ny, nx): sample (i, j, k) is ``volume[k, j, i]``, so x is the array's last
        axis, as in the files. The eight types int8 ... float64 (and bool) are read in place
        whatever the strides (C or Fortran order, ``vol[:, ::2, 10:200]``, negative steps);
        other types are converted first (a copy). The mesh is the same for every layout; the
        extractor is fastest when the last axis is contiguous. Otherwise (Fortran order) each
        range of planes is first copied, with x contiguous, into a window of about 4 MiB per
        thread: about twice the time of C order for bonsai 256^3 uint8 (5x read in place).
    iso : float
        The isovalue.
    spacing, origin : 3 floats, optional
        In the library's axis order (x, y, z), x being the array's last axis; default (1, 1, 1) and
        (0, 0, 0), or the Volume's. Positions are origin + direction @ (spacing * (i, j, k)).
    direction : 3x3 array, optional
        Column a is the world direction of +axis a; default the identity (or the Volume's). A
        mirroring frame reverses the winding so that normals keep pointing from above to below.
    method : {'cmc33', 'mc33-lewiner', 'mc'}
        'cmc33' (default) is topologically correct; the others are for comparison.
    normals : bool
        Also compute unit per-vertex normals from the field's gradient (``mesh.normals``).
    threads : int
        Worker threads, 0 (default) for every core.
    progress : callable, optional
        Called on the calling thread as ``progress(fraction)`` every few tens of milliseconds and
        with 1.0 at the end; return False to stop (CancelledError). Exceptions it raises stop the
        extraction and propagate.

    Returns
    -------
    Mesh
        ``mesh.vertices`` (V, 3) float32, ``mesh.triangles`` (F, 3) uint32, ``mesh.normals``: numpy
        arrays over the library's memory (no copy). Triangles wind counter-clockwise seen from the
        side the normals point to, from above ``iso`` to below.

    Raises
    ------
    ValueError
        A volume that is not 3D or has fewer than 2 samples on an axis, bad arguments,
        NaN or infinite samples (NonFiniteError names how many and the first as you index it,
        ``volume[z, y, x]``).
    KeyboardInterrupt
        Ctrl-C stops the extraction within a fraction of a second.

    The GIL is released while the library works.
    """
    name = "volume"
    if isinstance(volume, Volume):
        samples = volume.samples
        name = "volume.samples"
        spacing = volume.spacing if spacing is None else spacing
        origin = volume.origin if origin is None else origin
        direction = volume.direction if direction is None else direction
    else:
        samples = as_samples(volume)
    if progress is not None and not callable(progress):
        raise ValueError(f"progress {progress!r} is not callable")
    try:
        return _cmc33.extract(samples, float(iso), vec3((1, 1, 1) if spacing is None else spacing, "spacing"),
                              vec3((0, 0, 0) if origin is None else origin, "origin"),
                              IDENTITY if direction is None else mat3(direction), _method(method), bool(normals),
                              thread_count(threads), progress)
    except NonFiniteError:
        raise_non_finite(samples, name)  # names volume[z, y, x], not the library's (x, y, z)
        raise


def read_volume(path: PathLike, *, frame: Optional[int] = None, array: Optional[str] = None,
                series: Optional[str] = None, space: Optional[str] = None,
                spacing: Optional[Sequence[float]] = None, origin: Optional[Sequence[float]] = None,
                dims: Optional[Sequence[int]] = None, dtype: Any = None, endian: str = "little",
                header_bytes: int = 0) -> Volume:
    """Reads a volume as ``cmc33 extract`` and ``cmc33 info`` read it, the format told by the
    file's content before its name: NRRD (.nrrd, .nhdr), MetaImage (.mhd, .mha), VTK legacy (.vtk),
    NIfTI-1 and -2 (.nii, .nii.gz, .hdr + .img), NumPy (.npy), VTK XML ImageData (.vti), TIFF (a
    multi-page file or a folder of slices) and DICOM (a folder of slice files, a DICOMDIR or a
    multi-frame file; only when the package was built with GDCM, -DCMC33_WITH_GDCM=ON, else
    UnsupportedFormatError says so).

    Returns a Volume:

    * ``volume.samples``: the numpy array of shape (nz, ny, nx) over the library's memory (no
      copy): ``samples[k, j, i]`` is sample (i, j, k), x (the file's fastest axis) being the
      array's last axis. For a NIfTI file that is nibabel's ``img.get_fdata()`` transposed
      (``.T``); for a .npy file of shape (nz, ny, nx) it is that array.
    * ``volume.affine``: 4x4, index to world: the world position of ``samples[k, j, i]`` is
      ``affine @ (i, j, k, 1)``; its columns 0, 1, 2 are the steps along i = x, j = y, k = z, so it
      equals nibabel's ``img.affine`` for a NIfTI file. The same frame in parts:
      ``spacing``, ``origin`` and ``direction`` (x, y, z order).
    * ``volume.space_code``: the world space, "RAS" (NIfTI: x to the right, y anterior, z
      superior) or "LPS" (DICOM, NRRD's usual), or None when the file names no anatomical space
      (.npy, .vti, TIFF, a NIfTI with neither sform nor qform); ``volume.space`` is the name as the
      file gave it.
    * ``volume.frame_source``: where the frame came from ("sform (code 2: aligned)", "qform",
      "ImagePositionPatient/ImageOrientationPatient", "Origin, Spacing, Direction", ...).

    ``extract(volume, iso)`` uses that frame and places the vertices where ``cmc33 extract``
    places them for the same file and options.

    Parameters
    ----------
    frame : int, optional
        4-D files (NIfTI with dim[4] > 1, a 4-D .npy): the frame to read, from 0 (nibabel's
        ``img.dataobj[..., frame]``); required when the file holds several.
    array : str, optional
        .vti: the point-data array to read (default: the active scalars, else the only array).
    series : str, optional
        DICOM: the SeriesInstanceUID to read when the input holds several series.
    space : {'ras', 'lps'}, optional
        Moves the frame into that world space (negating x and y between RAS and LPS), as
        ``--space``; refused for a file that names no anatomical space. Default: the file's own.
    spacing, origin : 3 floats, optional
        The frame of formats that give none (.npy, TIFF; in x, y, z order), as ``--spacing`` and
        ``--origin``; refused for formats that give their own. For a headerless raw file,
        ``spacing`` is its spacing.
    dims, dtype, endian, header_bytes
        A headerless raw file (any name the formats above do not claim) needs ``dims`` (x, y,
        z) and ``dtype`` (a numpy type or "uint16", ...), and optionally ``endian`` ('little' or
        'big') and ``header_bytes`` to skip.

    Errors name the file, what is wrong and what was expected (FileError is an OSError; the
    format errors are ValueErrors).
    """
    raw_dims = None
    type_name = "uint8"
    if dims is not None:
        raw_dims = tuple(int(d) for d in dims)
        if len(raw_dims) != 3:
            raise ValueError(f"dims has {len(raw_dims)} values; expected 3 (x, y, z)")
        if dtype is None:
            raise ValueError("a headerless raw volume needs dtype as well as dims")
        type_name = np.dtype(dtype).name if not isinstance(dtype, str) else dtype
        if endian not in ("little", "big"):
            raise ValueError(f"endian {endian!r}; expected 'little' or 'big'")
        if origin is not None:
            raise ValueError("origin is for .npy and TIFF files; a headerless raw volume starts at 0")
    elif dtype is not None:
        raise ValueError("dtype is for headerless raw files, with dims; a file with a header gives its type")
    if frame is not None and (isinstance(frame, bool) or int(frame) != frame or frame < 0):
        raise ValueError(f"frame {frame!r}; expected a whole number from 0")
    for name, text in (("array", array), ("series", series)):
        if text is not None and (not isinstance(text, str) or not text):
            raise ValueError(f"{name} {text!r}; expected a non-empty string")
    target = None
    if space is not None:
        target = str(space).lower()
        if target not in ("ras", "lps"):
            raise ValueError(f"space {space!r}; expected 'ras' or 'lps'")
    try:
        volume = _cmc33.read_volume(os.fspath(path), raw_dims, type_name,
                                    None if spacing is None else vec3(spacing, "spacing"), endian, int(header_bytes),
                                    None if frame is None else int(frame), array or "", series or "",
                                    None if origin is None else vec3(origin, "origin"))
    except Error as e:
        # the readers' messages name the command line's options; here they are arguments
        text = _OPTION.sub(lambda m: f"{m[1]}={m[2] or ''}", str(e))
        if text == str(e):
            raise
        raise type(e)(text) from None
    if target is not None:
        if volume.space_code is None:
            raise InvalidArgumentError(
                f"{os.fspath(path)}: the file names no anatomical space (its frame has no orientation: "
                f"{volume.frame_source or 'no frame'}), so it cannot be converted to {target.upper()}; leave out space=")
        _cmc33.convert_space(volume, target)
    return volume


def write_volume(volume: Union[Volume, Any], path: PathLike, *, spacing: Optional[Sequence[float]] = None,
                 origin: Optional[Sequence[float]] = None, direction: Any = None) -> None:
    """Writes a volume: .nrrd, .nhdr (+ .raw), .mhd (+ .raw), .mha, .vtk or .raw, by extension.

    ``volume`` is a Volume or a (nz, ny, nx) array (copied once into the library's layout) with
    its frame given here in x, y, z order as for extract().
    """
    if not isinstance(volume, Volume) or spacing is not None or origin is not None or direction is not None:
        base = volume if isinstance(volume, Volume) else None
        samples = np.ascontiguousarray(as_samples(base.samples if base else volume, "samples"))
        default_spacing, default_origin, default_direction = (
            (base.spacing, base.origin, base.direction) if base else ((1, 1, 1), (0, 0, 0), IDENTITY))
        volume = Volume(samples, vec3(default_spacing if spacing is None else spacing, "spacing"),
                        vec3(default_origin if origin is None else origin, "origin"),
                        mat3(default_direction if direction is None else direction))
    _cmc33.write_volume(volume, os.fspath(path))


def read_mesh(path: PathLike) -> Mesh:
    """Reads a mesh: .ply (ASCII or binary), .obj, .stl (binary or ASCII; coincident vertices
    welded) or .off. Polygons are fanned into triangles."""
    return _cmc33.read_mesh(os.fspath(path))


def write_mesh(mesh: MeshLike, path: PathLike, *, ascii: bool = False) -> None:
    """Writes a mesh by extension: .ply (binary little-endian, or ASCII with ``ascii=True``),
    .obj, .stl (binary) or .off; normals where the format has them (PLY, OBJ). The file is written
    beside the target and renamed, so a failed write leaves nothing behind.

    ``mesh`` is a Mesh, or (vertices, triangles[, normals]) arrays (copied), e.g. what
    marching_cubes returns. The bytes are those of ``cmc33 extract ... -o FILE``.
    """
    _cmc33.write_mesh(as_mesh(mesh), os.fspath(path), bool(ascii))


def mesh_topology(mesh: MeshLike) -> MeshTopology:
    """Combinatorial invariants of a mesh: V, E, F, Euler characteristic, components, closed
    components, b1, boundary edges and loops, non-manifold edges and vertices, degenerate
    triangles, closed, oriented. ``mesh`` is a Mesh or (vertices, triangles) arrays."""
    return _cmc33.mesh_topology(as_mesh(mesh))


def mesh_geometry(mesh: MeshLike, *, threads: int = 0, examples: int = 8) -> MeshGeometry:
    """Checks the mesh as it sits in space, with exact predicates on its float positions:
    coincident vertices, zero-area triangles, pairs of triangles that meet improperly (up to
    ``examples`` of them listed), and the topology after welding by position.
    ``result.embedded`` is True when there is none of the three. ``mesh`` is a Mesh or
    (vertices, triangles) arrays, e.g. scikit-image's output."""
    if examples < 0:
        raise ValueError(f"examples {examples}; expected 0 or more")
    return _cmc33.mesh_geometry(as_mesh(mesh), thread_count(threads), int(examples))


def field_topology(volume: Union[Volume, Any], iso: float, *, max_refinement: int = 256) -> FieldTopology:
    """The invariants the level set ``f = iso`` of the trilinear interpolant must have (Euler
    characteristic, b0, b1, b2, boundary loops), computed from the samples alone, exactly, with
    the same sign rule (a sample equal to ``iso`` counts as above). A mesh of cmc33 matches them:
    compare with mesh_topology(). ``volume`` as in extract() (read in place); the frame does not
    matter. The GIL is released; this call cannot be interrupted."""
    samples = volume.samples if isinstance(volume, Volume) else as_samples(volume)
    try:
        return _cmc33.field_topology(samples, float(iso), int(max_refinement))
    except NonFiniteError:
        raise_non_finite(samples, "volume.samples" if isinstance(volume, Volume) else "volume")
        raise


def analyze_cell(values: Sequence[float], iso: float = 0.0, *, method: str = "cmc33") -> CellReport:
    """Every decision the extractor takes for one cell: case, subcase, the six face tests, the
    interior test and the cell's triangles in the unit cube. ``values`` are the 8 corner values,
    corner c at (c & 1, c >> 1 & 1, c >> 2 & 1), as ``cmc33 cell`` takes them."""
    corners = tuple(float(v) for v in values)
    if len(corners) != 8:
        raise ValueError(f"values has {len(corners)} numbers; expected the 8 corner values")
    return _cmc33.analyze_cell(corners, float(iso), _method(method))


def random_field(kind: str, n: int, *, seed: int = 1, size: int = 5) -> Volume:
    """Item ``n`` (>= 1) of the verifier's random fields: kind 'cell' (2x2x2), 'grid', 'closed' or
    'ties' (size^3), isovalue 0; the same field verify() checks for that seed."""
    return _cmc33.random_field(kind, int(n), int(seed), int(size))


def verify(*, cells: int = 0, grids: int = 0, closed: int = 0, ties: int = 0, size: int = 5, seed: int = 1,
           methods: Sequence[str] = ("cmc33",), threads: int = 0, failures_dir: Optional[PathLike] = None,
           max_failures: int = 20,
           progress: Optional[Callable[[int, int, int, float], None]] = None) -> VerifyReport:
    """The topology stress test (``cmc33 verify``): random cells, grids, closed grids and tie
    grids; for each, the field's expected topology, the mesh of every method, and the comparison
    (invariants, manifold, embedded). ``report.passed`` is True when no method mismatched.

    ``progress(done, total, mismatched, seconds)`` is called about every 0.2 s on this thread.
    Failing fields are written to ``failures_dir`` if given. The GIL is released; a Ctrl-C takes
    effect when the run ends (the verifier cannot be stopped midway).
    """
    return _cmc33.verify([_method(m) for m in methods], int(cells), int(grids), int(closed), int(ties), int(size),
                         int(seed), thread_count(threads), "" if failures_dir is None else os.fspath(failures_dir),
                         int(max_failures), progress)
