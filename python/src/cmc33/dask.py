"""Isosurfaces of Dask arrays chunk by chunk: ``cmc33.dask.extract_dask(array, iso)``.

Each block of the array's chunking is extracted where Dask runs it (threads, processes or a
``dask.distributed`` cluster) from its chunk and the halo its cells need, and the driver merges
the blocks' meshes by grid edge. The result equals ``cmc33.extract`` of the whole array as sets:
the same vertex positions bit for bit, the same triangles (winding included), the same normals;
only the order of vertices and triangles differs. docs/dask.md has the rules and the numbers.
"""
from __future__ import annotations

import math
from typing import Any, List, Optional, Sequence, Tuple

import numpy as np

from . import _cmc33
from ._api import METHODS, _method
from ._arrays import vec3
from ._cmc33 import Mesh

__all__ = ["extract_dask", "blocks"]

#: A block: (numpy slices of its samples, global index of its first sample (x, y, z), the cells it
#: owns as local [lo, hi) in (x, y, z)).
Block = Tuple[Tuple[slice, slice, slice], Tuple[int, int, int], Tuple[int, int, int], Tuple[int, int, int]]


def _boundaries(chunks: Sequence[int]) -> List[Tuple[int, int]]:
    starts = np.concatenate([[0], np.cumsum(chunks)]).astype(int)
    return [(int(a), int(b)) for a, b in zip(starts[:-1], starts[1:])]


def blocks(shape: Sequence[int], chunks: Sequence[Sequence[int]], normals: bool = False) -> List[Block]:
    """The blocks of an array of ``shape`` (nz, ny, nx) chunked as ``chunks`` (Dask's tuple of
    tuples): one per chunk that owns a cell. A chunk owns the cells whose lowest corner is one of
    its samples; it reads them and one sample more on the upper side of each axis (the cells'
    upper corners), plus one more on each side with normals (central differences)."""
    lower_halo = 1 if normals else 0
    upper_halo = 2 if normals else 1
    per_axis = []
    for n, axis_chunks in zip(shape, chunks):
        ranges = []
        for start, end in _boundaries(axis_chunks):
            cells_end = min(end, n - 1)
            if cells_end <= start:
                continue  # a last chunk of one sample: its cells belong to no one
            lo, hi = max(start - lower_halo, 0), min(cells_end + upper_halo, n)
            ranges.append((slice(lo, hi), lo, start - lo, cells_end - lo))
        per_axis.append(ranges)
    out = []
    for z in per_axis[0]:
        for y in per_axis[1]:
            for x in per_axis[2]:
                out.append(((z[0], y[0], x[0]), (x[1], y[1], z[1]), (x[2], y[2], z[2]), (x[3], y[3], z[3])))
    return out


def _extract_block(samples: Any, iso: float, method: str, lower: Sequence[int], own_lo: Sequence[int],
                   own_hi: Sequence[int], dims: Sequence[int], spacing: Sequence[float], origin: Sequence[float],
                   normals: bool, bound: float) -> Tuple[Any, ...]:
    """One block on a worker: keys, positions, normals (or None), triangles, sample bound."""
    from ._arrays import as_samples
    return _cmc33.extract_block(as_samples(np.asarray(samples)), iso, method, tuple(lower), tuple(own_lo), tuple(own_hi),
                                tuple(dims), tuple(spacing), tuple(origin), normals, bound)


def _run(tasks: List[Any], scheduler: Optional[str]) -> List[Tuple[Any, ...]]:
    """Computes the delayed blocks. On a distributed client the results are gathered as they end
    and released at once, so no worker keeps more than the blocks it is running."""
    import dask
    if scheduler is None:
        try:
            from distributed import default_client
            client = default_client()
        except (ImportError, ValueError):
            client = None
        if client is not None:
            from distributed import as_completed
            futures = client.compute(tasks)
            index = {f.key: i for i, f in enumerate(futures)}
            results: List[Any] = [None] * len(tasks)
            for future in as_completed(futures):
                results[index[future.key]] = future.result()
                future.release()
            return results
    return list(dask.compute(*tasks, scheduler=scheduler))


def _scale_changes(bound: float, spacing: Sequence[float]) -> bool:
    """True when the extractor scales its gradients for samples as large as ``bound`` (the
    library's gradient_scale: only near the double range)."""
    inverse = max(1 / abs(s) for s in spacing)
    if not (bound > 0) or not math.isfinite(inverse) or not (inverse > 0):
        return False
    return math.frexp(bound)[1] - 1 + math.frexp(inverse)[1] - 1 + 5 > 1000


def extract_dask(array: Any, iso: float, *, spacing: Optional[Sequence[float]] = None,
                 origin: Optional[Sequence[float]] = None, method: str = "cmc33", normals: bool = False,
                 scheduler: Optional[str] = None) -> Mesh:
    """Extracts the isosurface ``f = iso`` of a 3-D Dask array (shape (nz, ny, nx), any chunking;
    e.g. ``dask.array.from_zarr``) block by block, as ``cmc33.extract`` does for a whole array.

    Parameters are those of ``cmc33.extract`` (spacing and origin in x, y, z order; no direction:
    the frame is axis-aligned) plus ``scheduler``: Dask's scheduler name ("threads", "processes",
    "synchronous"); by default the active ``dask.distributed`` client if there is one (results
    are then gathered block by block as they end), else Dask's default.

    Each chunk's block reads its samples, one more on the upper side of each axis and, with
    ``normals``, one more on each side: a worker holds the chunks the block touches, the block
    and its mesh. The driver holds the merged mesh (about twice while merging).

    Returns a Mesh whose vertex and triangle sets equal those of ``cmc33.extract(array, iso,
    ...)`` bit for bit (and the normals, with ``normals=True``): vertices and triangles block by
    block, in the chunks' order.
    """
    import dask
    import dask.array as da

    arr = da.asarray(array)
    if arr.ndim != 3:
        raise ValueError(f"array has {arr.ndim} dimensions; expected 3 (nz, ny, nx)")
    if min(arr.shape) < 2:
        raise ValueError(f"array has shape {arr.shape}; expected at least 2 samples on each axis")
    if np.dtype(arr.dtype).kind not in "biuf":
        raise ValueError(f"array has type {arr.dtype}; expected numbers")
    method = _method(method)
    if method not in METHODS:
        raise ValueError(f"method {method!r}; expected one of {', '.join(METHODS)}")
    spacing_v = tuple(vec3((1, 1, 1) if spacing is None else spacing, "spacing"))
    origin_v = tuple(vec3((0, 0, 0) if origin is None else origin, "origin"))
    nz, ny, nx = (int(n) for n in arr.shape)
    dims = (nx, ny, nz)
    parts = blocks(arr.shape, arr.chunks, normals)
    iso = float(iso)
    if not math.isfinite(iso):
        raise ValueError(f"iso {iso}; expected a finite number")

    def run(bound: float) -> List[Tuple[Any, ...]]:
        task = dask.delayed(_extract_block, pure=True)
        tasks = [task(arr[s], iso, method, lower, lo, hi, dims, spacing_v, origin_v, bool(normals), bound)
                 for s, lower, lo, hi in parts]
        return _run(tasks, scheduler)

    results = run(0.0)
    if normals:
        # the whole-array extraction scales every gradient by the largest sample's bound
        bound = max(r[4] for r in results)
        if any(_scale_changes(bound, spacing_v) != _scale_changes(r[4], spacing_v) for r in results):
            results = run(bound)
    return _merge(results, bool(normals))


def _merge(results: List[Tuple[Any, ...]], normals: bool) -> Mesh:
    """The blocks' meshes as one, without a global sort: each vertex is kept from the one block
    that owns it (flag 1), in block order; the other copies (the upper faces' vertices a block
    reads in its halo) are found among the owners' exported vertices (flag 2: those on a block's
    lower faces), a small sorted table."""
    owned = [(r[5] & 1).astype(bool) for r in results]
    counts = [int(o.sum()) for o in owned]
    bases = np.concatenate([[0], np.cumsum(counts)]).astype(np.int64)
    exported_keys, exported_ids = [], []
    for r, o, base in zip(results, owned, bases):
        ids = np.full(len(o), -1, np.int64)
        ids[o] = base + np.arange(int(o.sum()), dtype=np.int64)
        e = (r[5] & 2).astype(bool)
        exported_keys.append(r[0][e])
        exported_ids.append(ids[e])
    table_keys = np.concatenate(exported_keys) if results else np.zeros(0, np.int64)
    table_ids = np.concatenate(exported_ids) if results else np.zeros(0, np.int64)
    order = np.argsort(table_keys, kind="stable")
    table_keys, table_ids = table_keys[order], table_ids[order]
    total = int(bases[-1]) if results else 0
    vertices = np.empty((total, 3), np.float32)
    merged_normals = np.empty((total, 3), np.float32) if normals else None
    triangles = np.empty((sum(len(r[3]) for r in results), 3), np.uint32)
    t = 0
    for r, o, base in zip(results, owned, bases):
        local = np.empty(len(o), np.int64)
        local[o] = base + np.arange(int(o.sum()), dtype=np.int64)
        others = ~o
        if others.any():
            keys = r[0][others]
            at = np.searchsorted(table_keys, keys)
            at = np.minimum(at, max(len(table_keys) - 1, 0))
            if len(table_keys) == 0 or not np.array_equal(table_keys[at], keys):
                raise RuntimeError("cmc33.dask: a seam vertex has no owner among the blocks (a bug)")
            local[others] = table_ids[at]
        vertices[base:base + len(local[o])] = r[1][o]
        if normals:
            merged_normals[base:base + len(local[o])] = r[2][o]
        triangles[t:t + len(r[3])] = local[r[3]]
        t += len(r[3])
    return Mesh(vertices, triangles, merged_normals)
