"""Label maps: every structure of a segmentation in one pass (cmc33::label_surfaces, docs/labels.md)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Dict, Iterable, List, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

from . import _cmc33
from ._arrays import IDENTITY, as_samples, mat3, thread_count, vec3
from ._cmc33 import Mesh, Volume

#: "all", "1,3,7-9" (the command line's --labels), one label, or labels and (first, last) ranges.
LabelSelection = Union[str, int, Iterable[Union[int, Tuple[int, int]]]]


@dataclass(frozen=True)
class LabelSurfaces:
    """What :func:`label_surfaces` returns.

    interfaces : Mesh
        Every interface triangle with a selected label on a side, once, welded by grid position;
        its normal (counter-clockwise winding) points into ``front[t]``.
    front, behind : (F,) int64 arrays
        The labels on the two sides of each triangle of ``interfaces``.
    surfaces : dict label -> Mesh, or None
        Each selected label's closed surface (closed except on the volume's box), wound so that
        normals point out of the label; None when asked for ``surfaces=False``.
    present : tuple of int
        Every label in the volume, ascending (the background too).
    selected : tuple of int
        The labels that got surfaces, ascending.
    cells_two_labels, cells_many_labels, cells_with_core : int
        Cells holding two labels (cmc33's triangulation), three or more (cones from the centre, or a
        core), and of those the cells cut around a core (where a label's part of the cell's surface
        is not one disk; docs/labels.md).
    """

    interfaces: Mesh
    front: npt.NDArray[np.int64]
    behind: npt.NDArray[np.int64]
    surfaces: Optional[Dict[int, Mesh]]
    present: Tuple[int, ...]
    selected: Tuple[int, ...]
    cells_two_labels: int
    cells_many_labels: int
    cells_with_core: int


def _ranges(labels: LabelSelection) -> List[Tuple[int, int]]:
    """The selection as (first, last) ranges; [] for every label."""
    if isinstance(labels, str):
        return [tuple(r) for r in _cmc33.parse_label_ranges(labels)]  # type: ignore[misc]
    if isinstance(labels, (int, np.integer)) and not isinstance(labels, bool):
        return [(int(labels), int(labels))]
    ranges: List[Tuple[int, int]] = []
    try:
        items = list(labels)
    except TypeError:
        raise ValueError(f"labels {labels!r}; expected 'all', a list such as '1,3-5', a label or a sequence of "
                         "labels and (first, last) ranges") from None
    for item in items:
        if isinstance(item, (int, np.integer)) and not isinstance(item, bool):
            ranges.append((int(item), int(item)))
            continue
        pair = list(item) if isinstance(item, (tuple, list)) else None
        if pair is None or len(pair) != 2 or not all(isinstance(v, (int, np.integer)) for v in pair):
            raise ValueError(f"labels: {item!r} is neither a label nor a (first, last) range of labels")
        if pair[0] > pair[1]:
            raise ValueError(f"labels: the range {tuple(pair)!r} ends before it starts")
        ranges.append((int(pair[0]), int(pair[1])))
    if not ranges:
        raise ValueError("labels: the selection is empty; pass 'all' for every label")
    return ranges


def _label_samples(labels: Any) -> np.ndarray:
    """An integer array the library reads in place (as_samples: int8 ... uint32 in any strides,
    bool as uint8); int64 and uint64 (scikit-image's and scipy's label arrays) are first converted
    to the smaller of int32 / uint32 that holds their values (a copy)."""
    array = np.asarray(labels)
    dtype = array.dtype
    if dtype != np.bool_ and dtype.kind not in "iu":
        raise ValueError(f"labels have type {dtype}; a label map needs integer samples")
    if dtype.itemsize == 8 and array.ndim == 3:
        low, high = (int(array.min()), int(array.max())) if array.size else (0, 0)
        fits = [t for t in (np.int32, np.uint32) if np.iinfo(t).min <= low and high <= np.iinfo(t).max]
        if not fits:
            raise ValueError(f"labels hold values from {low} to {high}; a label map's values must fit in int32 "
                             "or uint32")
        array = array.astype(fits[0])
    return as_samples(array, "labels")


def label_surfaces(labels: Union[Volume, Any], *, select: LabelSelection = "all", background: int = 0,
                   spacing: Optional[Sequence[float]] = None, origin: Optional[Sequence[float]] = None,
                   direction: Any = None, normals: bool = False, surfaces: bool = True,
                   smooth: float = 0.0, threads: int = 0) -> LabelSurfaces:
    """The surfaces of every label of a segmentation, from one pass (cmc33::label_surfaces).

    The labels partition space (each point belongs to the label whose trilinearly interpolated
    indicator is largest, ties to the lower label); neighbouring labels share their interface
    triangles, so the union of the surfaces welded by position is watertight, each label's
    surface is closed except on the volume's box, and nothing crosses. In a cell with two labels
    the interface has the topology of the indicator's trilinear level set (cmc33's decisions).
    The output is the same for every thread count.

    Parameters
    ----------
    labels : cmc33.Volume or 3D integer array
        A Volume (read_volume; its frame is used unless overridden here) or an array of shape
        (nz, ny, nx): sample (i, j, k) is ``labels[k, j, i]``. int8 ... uint32 are read in place
        whatever the strides; bool is read as uint8; int64 and uint64 are converted to int32 or
        uint32 (a copy) when their values fit. Floats are refused.
    select : str, int or sequence
        The labels that get surfaces: "all" (default: every label present but ``background``),
        "1,3,7-9", one label, or a sequence of labels and (first, last) ranges.
    background : int
        The label that gets no surface (default 0; it still takes part in the partition).
    spacing, origin, direction
        The frame, as in :func:`extract`.
    normals : bool
        Per-vertex unit normals on every mesh (each label's pointing out of it).
    surfaces : bool
        Also make each selected label's closed surface (default True); False gives only the
        interfaces and their labels.
    smooth : float
        Sigma in voxels of a Gaussian each label's indicator is filtered by first (0, the default:
        none): each sample then takes the label whose filtered indicator is largest, and the
        interfaces pass where two labels' filtered indicators are equal, with the same partition
        guarantees (docs/labels.md, "Smooth labels").
    threads : int
        Worker threads, 0 (default) for every core.

    Returns
    -------
    LabelSurfaces

    The GIL is released while the library works.
    """
    if isinstance(labels, Volume):
        samples = _label_samples(labels.samples)
        spacing = labels.spacing if spacing is None else spacing
        origin = labels.origin if origin is None else origin
        direction = labels.direction if direction is None else direction
    else:
        samples = _label_samples(labels)
    if isinstance(background, bool) or not isinstance(background, (int, np.integer)):
        raise ValueError(f"background {background!r}; expected an integer label")
    ranges = [] if isinstance(select, str) and select == "all" else _ranges(select)
    if isinstance(smooth, bool) or not isinstance(smooth, (int, float, np.integer, np.floating)):
        raise ValueError(f"smooth {smooth!r}; expected a number of voxels >= 0")
    result = _cmc33.label_surfaces(samples, vec3((1, 1, 1) if spacing is None else spacing, "spacing"),
                                   vec3((0, 0, 0) if origin is None else origin, "origin"),
                                   IDENTITY if direction is None else mat3(direction), int(background), ranges,
                                   bool(normals), thread_count(threads), bool(surfaces), float(smooth))
    interfaces, front, behind, per_label, present, selected, two, many, core = result
    return LabelSurfaces(interfaces, front, behind, per_label, tuple(present), tuple(selected), two, many, core)
