"""cmc33.marching_cubes: scikit-image's call, cmc33's mesh."""

from __future__ import annotations

import math
from typing import Any, Optional, Sequence, Tuple

import numpy as np

from . import _cmc33
from ._arrays import as_samples, raise_non_finite, thread_count, vec3
from ._errors import NonFiniteError

# scikit-image's method names and cmc33's own, to the method that runs.
_METHODS = {
    "cmc33": "cmc33",
    "lewiner": "cmc33",  # scikit-image's default: its MC33, here with the 2013 corrections
    "mc33-lewiner": "mc33-lewiner",
    "mc": "mc",
    "lorensen": "mc",
}


def _check_level(samples: np.ndarray, level: float, threads: int) -> None:
    """ValueError, as scikit-image raises it, for a level outside the data range."""
    low, high = _cmc33.value_range(samples, threads)
    if level < low or level > high:
        raise ValueError(f"Surface level must be within volume data range: level {level:g}, "
                         f"data from {low:g} to {high:g}")


def marching_cubes(volume: Any, level: Optional[float] = None, *, spacing: Sequence[float] = (1., 1., 1.),
                   gradient_direction: str = "descent", step_size: int = 1, allow_degenerate: bool = True,
                   method: str = "cmc33", mask: Any = None,
                   threads: int = 0) -> Tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Triangle mesh of an isosurface, as ``skimage.measure.marching_cubes`` returns it.

    A drop-in replacement: code that calls scikit-image's function with keyword arguments works
    unchanged after ``from cmc33 import marching_cubes``. The mesh is cmc33's: it has the topology
    of the level set of the trilinear interpolant (Marching Cubes 33 as corrected by Custodio et
    al. 2013), it is manifold, and it is embedded (no duplicate vertex, no zero-area triangle, no
    two triangles crossing), so welding it by position changes nothing.

    Parameters
    ----------
    volume : (M, N, P) array (or a cmc33.Volume: its samples; its frame is not used)
        The samples. int8, uint8, int16, uint16, int32, uint32, float32 and float64 (and bool) are
        read in place in any layout (C or Fortran order, slices such as ``vol[:, ::2, 10:200]``);
        other types are converted first (float16 to float32; int64, uint64 to float64). The
        arrays returned are the same for every layout; C order (last axis contiguous) is the
        fast one. Where the last axis is not contiguous (Fortran order), each range of planes is
        first copied, with x contiguous, into a window of about 4 MiB per thread (about 2x the
        time of C order for bonsai 256^3 uint8, instead of 5x read in place).
    level : float, optional
        The isovalue; default the middle of the data range, ``(min + max) / 2``. A value outside
        [min, max] raises ValueError, as in scikit-image.
    spacing : 3 floats, optional
        Distance between samples along the array's axes (M, N, P).
    gradient_direction : {'descent', 'ascent'}, optional
        The winding of ``faces``, as in scikit-image: with 'descent' (the object brighter than its
        surroundings) the right-hand normal of each face, ``cross(v1 - v0, v2 - v0)``, points into
        the brighter side; with 'ascent' it points out of it, along ``normals``.
    step_size : int, optional
        Use every step_size-th sample along each axis (coarser, faster), as in scikit-image.
    allow_degenerate : bool, optional
        Accepted for compatibility and ignored: the mesh never has a degenerate (zero-area)
        triangle, so there is nothing to remove.
    method : str, optional
        'cmc33' (default), and scikit-image's 'lewiner', which runs 'cmc33' too (the same
        algorithm with the corrections); 'lorensen' runs classic Marching Cubes ('mc'), also
        embedded but without the topological guarantees. 'mc33-lewiner' reproduces the flaws of
        the 2003 MC33 for comparison. scikit-image's private '_lorensen', which returns only
        (verts, faces), is refused (ValueError) rather than answered with four arrays.
    mask : (M, N, P) bool array, optional
        Keep only the cells where the mask is True at the cell's corner of largest index (this is
        what scikit-image's implementation reads), giving an open surface that ends at the masked
        region. Non-boolean masks are taken as ``mask != 0``.
    threads : int, optional
        cmc33 only: worker threads, 0 (default) for every core. The arrays are the same, byte for
        byte, for every count.

    Returns
    -------
    verts : (V, 3) float32 array
        Vertex positions in the array's axis order (M, N, P), scaled by ``spacing``.
    faces : (F, 3) int32 array
        Vertex indices per triangle (uint32 if the mesh ever has 2^31 vertices or more).
    normals : (V, 3) float32 array
        Unit normals, pointing from higher to lower values (as scikit-image's do).
    values : (V,) float32 array
        scikit-image's measure of the data around each vertex: the largest range (largest minus
        smallest of its 8 samples) among the cells whose triangles use the vertex.

    Raises
    ------
    ValueError
        A volume that is not 3D or smaller than 2x2x2, ``level`` outside the data range, a bad
        ``spacing``, ``step_size``, ``gradient_direction``, ``method`` or mask shape, NaN or
        infinite samples (cmc33.NonFiniteError, a ValueError, naming the first as ``volume[i, j, k]``
        in your array's axis order).
    RuntimeError
        No surface at ``level``, as scikit-image.
    KeyboardInterrupt
        Ctrl-C stops a long extraction within a fraction of a second.

    Notes
    -----
    Where scikit-image's conventions would break cmc33's guarantees, cmc33 keeps its own:

    * A sample equal to ``level`` counts as above it (scikit-image: strictly above), so integer
      data at an integer level has no holes or duplicate faces. Consequently ``level`` equal to
      the maximum gives the surface around the largest samples, and ``level`` equal to the
      minimum gives no surface (RuntimeError).
    * Vertices lie where the linear interpolation along each grid edge puts them, as in
      scikit-image, but never closer than 2^-10 of an edge to a sample, so that ties cannot
      collapse triangles. At half-integer levels of 8-bit data this never moves a vertex.
    * Cells whose topology needs them get vertices inside the cell (tunnels, fans).
    * ``normals`` come from central differences of the samples, in the scaled space (scikit-image
      ignores ``spacing`` in its normals).
    * ``verts`` is float32 also with a ``spacing`` (scikit-image then returns float64); all four
      arrays are C-contiguous (scikit-image returns reversed views).
    * With ``mask`` the whole volume is extracted and the masked cells' triangles dropped: a mask
      changes the mesh as in scikit-image but does not save time.

    Examples
    --------
    >>> import numpy as np, cmc33
    >>> z, y, x = np.mgrid[-1:1:32j, -1:1:32j, -1:1:32j]
    >>> verts, faces, normals, values = cmc33.marching_cubes(x**2 + y**2 + z**2, 0.5)
    """
    samples = as_samples(volume.samples if isinstance(volume, _cmc33.Volume) else volume)
    if min(samples.shape) < 2:
        raise ValueError(f"volume has shape {samples.shape}; expected at least 2x2x2 samples")
    spacing = vec3(spacing, "spacing")
    try:
        step = int(step_size)  # as scikit-image: 2.0 is 2
    except (TypeError, ValueError):
        raise ValueError(f"step_size {step_size!r} is not an integer") from None
    if step < 1:
        raise ValueError(f"step_size {step}; expected at least one")
    if gradient_direction not in ("descent", "ascent"):
        raise ValueError(f"gradient_direction {gradient_direction!r}; expected 'descent' or 'ascent'")
    if method == "_lorensen":
        # scikit-image's private name returns (verts, faces) only: the 4-tuple here would break its callers' unpacking
        raise ValueError("method '_lorensen' is scikit-image's private classic Marching Cubes, which returns "
                         "(verts, faces) only; use method='lorensen' (classic Marching Cubes, the four arrays)")
    if method not in _METHODS:
        raise ValueError(f"method {method!r}; expected one of {', '.join(repr(m) for m in _METHODS)}")
    threads = thread_count(threads)
    mask_cells = None
    if mask is not None:
        mask = np.asarray(mask)
        if mask.shape != samples.shape:
            raise ValueError(f"volume and mask must have the same shape: volume {samples.shape}, mask {mask.shape}")
        if mask.dtype != np.bool_:
            mask = mask != 0
        # cell (k, j, i) of the stepped grid is kept where the mask holds at its far corner
        mask_cells = mask[step::step, step::step, step::step]

    if level is None:
        low, high = _cmc33.value_range(samples, threads)
        level = 0.5 * (low + high)
    else:
        # No pass over the data for its range here: a mesh with a triangle has a sample at or
        # above the level and one below it, so min < level <= max. Only an empty mesh needs the
        # range, to tell a level outside it (ValueError) from no surface (RuntimeError).
        level = float(level)
        if not math.isfinite(level):
            raise ValueError(f"Surface level must be within volume data range: level {level:g}")

    grid = samples[::step, ::step, ::step] if step > 1 else samples
    if min(grid.shape) < 2:
        _check_level(samples, level, threads)
        raise RuntimeError(f"No surface found at the given iso value: step_size {step} leaves the grid "
                           f"{grid.shape}, with fewer than 2 samples along an axis")
    try:
        verts, faces, normals, values = _cmc33.marching_cubes(
            grid, level, tuple(s * step for s in spacing), _METHODS[method], gradient_direction == "descent",
            mask_cells, threads, None)
    except NonFiniteError:
        raise_non_finite(samples, "volume", step)  # names volume[z, y, x], not the library's (x, y, z)
        raise
    if len(faces) == 0:
        _check_level(samples, level, threads)
        raise RuntimeError(f"No surface found at the given iso value: level {level:g}")
    return verts, faces, normals, values
