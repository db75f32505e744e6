"""Shared fixtures and helpers of the cmc33 package's tests (run by scripts/test-python.sh against
the installed package, not the source tree)."""

import os
from pathlib import Path

import numpy as np
import pytest

REPO = Path(__file__).resolve().parents[2]
BUCKY = REPO / "data" / "Bucky_32x32x32_uint8.nrrd"
SHARED_VOLUMES = Path(os.environ.get("CMC33_SHARED", REPO.parent / "shared")) / "data" / "volumes"

# The eight sample types the library reads in place.
DTYPES = ["int8", "uint8", "int16", "uint16", "int32", "uint32", "float32", "float64"]


@pytest.fixture(scope="session")
def cli():
    """The command-line tool, for byte-for-byte comparisons: $CMC33_CLI, else build/cli/cmc33."""
    path = Path(os.environ.get("CMC33_CLI", REPO / "build" / "cli" / "cmc33"))
    if not path.is_file():
        pytest.skip(f"no cmc33 command-line tool at {path} (set CMC33_CLI; scripts/test-python.sh builds it)")
    return path


@pytest.fixture(scope="session")
def skimage_mc():
    measure = pytest.importorskip("skimage.measure", reason="scikit-image (Debian python3-skimage)")
    return measure.marching_cubes


def shared_volume(name):
    """A volume of ../shared/data/volumes, or a skip naming it."""
    path = SHARED_VOLUMES / name
    if not path.is_file():
        pytest.skip(f"{path} is not there (the shared volumes are beside the repository)")
    return path


def ellipsoid(shape=(30, 34, 38), radii=(0.8, 0.65, 0.9), dtype=np.float64):
    """A smooth field on a non-cubic grid, larger inside: 100 at the centre, 0 on the
    ellipsoid (radii are fractions of the half-extent along each array axis)."""
    axes = [np.linspace(-1, 1, n) / r for n, r in zip(shape, radii)]
    a, b, c = np.meshgrid(*axes, indexing="ij")
    return (100 * (1 - (a * a + b * b + c * c))).astype(dtype)


def uint8_blobs(shape=(36, 40, 44), seed=3):
    """Integer data with several blobs and tunnels: smoothed noise scaled to 0..255."""
    rng = np.random.default_rng(seed)
    noise = rng.random(tuple(n // 4 + 2 for n in shape))
    # trilinear upsampling of coarse noise gives smooth integer data with many ambiguous cells
    from itertools import product
    coords = [np.linspace(0, n // 4 + 1 - 1e-9, n) for n in shape]
    out = np.zeros(shape)
    i0 = [np.floor(c).astype(int) for c in coords]
    f = [c - i for c, i in zip(coords, i0)]
    for dx, dy, dz in product((0, 1), repeat=3):
        w = (np.where(dx, f[0], 1 - f[0])[:, None, None] * np.where(dy, f[1], 1 - f[1])[None, :, None] *
             np.where(dz, f[2], 1 - f[2])[None, None, :])
        out += w * noise[np.ix_(i0[0] + dx, i0[1] + dy, i0[2] + dz)]
    return np.round(255 * (out - out.min()) / (out.max() - out.min())).astype(np.uint8)


def edge_vertices(verts, spacing=(1.0, 1.0, 1.0)):
    """{(i, j, k, axis): position along the axis} for the vertices on grid edges (two coordinates
    on the grid), in index units; and the number of other (cell-interior) vertices."""
    index = np.asarray(verts, dtype=np.float64) / np.asarray(spacing, dtype=np.float64)
    rounded = np.round(index)
    on_grid = np.abs(index - rounded) < 1e-6
    edges = {}
    interior = 0
    for p, r, g in zip(index, rounded, on_grid):
        if g.sum() != 2:
            interior += 1
            continue
        axis = int(np.flatnonzero(~g)[0])
        key = [int(x) for x in r]
        key[axis] = int(np.floor(p[axis]))
        edges[(key[0], key[1], key[2], axis)] = p[axis]
    return edges, interior


def facing(verts, faces, normals):
    """Fraction of faces whose right-hand normal agrees with their vertices' normals."""
    v = np.asarray(verts, dtype=np.float64)
    f = np.asarray(faces, dtype=np.int64)
    n = np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]])
    return float(np.mean((n * np.asarray(normals)[f].sum(axis=1)).sum(axis=1) > 0))
