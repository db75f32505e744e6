"""Arguments as the compiled module takes them: sample arrays read in place, frames, thread counts."""

from __future__ import annotations

import operator
from typing import Any, Sequence, Tuple

import numpy as np

from ._errors import NonFiniteError

Vec3 = Tuple[float, float, float]
Mat3 = Tuple[Vec3, Vec3, Vec3]

IDENTITY: Mat3 = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))

#: The sample types the library reads in place (the C++ library's eight types).
IN_PLACE_TYPES = tuple(np.dtype(t) for t in ("int8", "uint8", "int16", "uint16", "int32", "uint32",
                                              "float32", "float64"))


def as_samples(volume: Any, what: str = "volume") -> np.ndarray:
    """The 3D array the compiled module reads: ``volume`` itself, or a view of it, whenever its
    samples are one of the eight types of IN_PLACE_TYPES (or bool, read as uint8) in the machine's
    byte order and aligned, whatever its strides (C or Fortran order, slices with steps, negative
    steps). Anything else is converted, which copies it: float16 to float32; int64, uint64,
    longdouble and object arrays to float64 (exact up to 2^53); the other byte order to the
    machine's. Raises ValueError for arrays that are not 3D or not real numbers."""
    array = np.asarray(volume)  # a subclass (memmap, ...) becomes a base-class view: no copy
    if array.ndim != 3:
        raise ValueError(f"{what} has {array.ndim} dimensions (shape {array.shape}); expected a 3D array")
    dtype = array.dtype
    if dtype == np.bool_:
        return array.view(np.uint8)
    if dtype.kind not in "iufO":
        raise ValueError(f"{what} has samples of type {dtype}; expected integers or floating-point numbers")
    if dtype.kind in "iuf" and dtype.newbyteorder("=") in IN_PLACE_TYPES:
        if not dtype.isnative:
            array = array.astype(dtype.newbyteorder("="))
        if not array.flags.aligned:
            array = np.ascontiguousarray(array)
        return array
    target = np.float32 if dtype.kind == "f" and dtype.itemsize < 4 else np.float64
    try:
        return np.ascontiguousarray(array, dtype=target)
    except (TypeError, ValueError) as e:
        raise ValueError(f"{what} has samples of type {dtype} that are not numbers: {e}") from None


def vec3(value: Any, name: str) -> Vec3:
    """Three floats, or ValueError naming ``name``."""
    try:
        items = tuple(float(v) for v in value)
    except (TypeError, ValueError):
        raise ValueError(f"{name} {value!r} is not three numbers") from None
    if len(items) != 3:
        raise ValueError(f"{name} has {len(items)} values; expected 3")
    return items  # type: ignore[return-value]


def mat3(value: Any, name: str = "direction") -> Mat3:
    """A 3x3 matrix as three rows of floats, or ValueError."""
    try:
        rows = tuple(tuple(float(v) for v in row) for row in np.asarray(value, dtype=float))
    except (TypeError, ValueError):
        raise ValueError(f"{name} is not a 3x3 matrix of numbers") from None
    if len(rows) != 3 or any(len(row) != 3 for row in rows):
        raise ValueError(f"{name} has shape {np.shape(value)}; expected (3, 3)")
    return rows  # type: ignore[return-value]


def thread_count(threads: Any) -> int:
    """A thread count: 0 (all cores) up to 1024."""
    try:
        n = operator.index(threads)
    except TypeError:
        raise ValueError(f"threads {threads!r} is not an integer") from None
    if not 0 <= n <= 1024:
        raise ValueError(f"threads {n}; expected 0 (all cores) to 1024")
    return n


def method_name(method: str, accepted: Sequence[str]) -> str:
    if method not in accepted:
        raise ValueError(f"method {method!r}; expected one of {', '.join(repr(m) for m in accepted)}")
    return method


def raise_non_finite(samples: np.ndarray, name: str, step: int = 1) -> None:
    """Raises NonFiniteError counting the NaN and infinite samples the library read (every
    ``step``-th along each axis) and naming the first (C order) as the caller indexes the array,
    ``name[z, y, x]``; returns if there is none (the library's error was about something else).
    The library's own message gives (x, y, z), its axis order, which a numpy user would misread."""
    if samples.dtype.kind != "f":
        return
    read = samples[::step, ::step, ::step] if step > 1 else samples
    bad = ~np.isfinite(read)
    count = int(np.count_nonzero(bad))
    if count == 0:
        return
    first = [int(i) * step for i in np.unravel_index(int(np.argmax(bad)), bad.shape)]
    noun = "sample is" if count == 1 else "samples are"
    raise NonFiniteError(f"{count} {noun} NaN or infinite, the first at {name}[{first[0]}, {first[1]}, {first[2]}]; "
                         "cmc33 needs finite samples")
