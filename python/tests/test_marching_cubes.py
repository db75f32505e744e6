"""cmc33.marching_cubes against skimage.measure.marching_cubes: agreement where both are right,
and scikit-image's conventions one by one."""

import inspect

import numpy as np
import pytest

import cmc33
from conftest import BUCKY, edge_vertices, ellipsoid, facing, uint8_blobs

CLAMP = 2.0 ** -10  # docs/conventions.md: edge vertices stay this far (of an edge) off the samples


def bucky():
    return cmc33.read_volume(BUCKY).samples


def volumes_where_both_are_right():
    """(volume, level): half-integer levels of integer data, and a smooth float field."""
    return [pytest.param(bucky(), 100.5, id="bucky"), pytest.param(uint8_blobs(), 127.5, id="blobs"),
            pytest.param(ellipsoid(), 0.25, id="ellipsoid")]


@pytest.mark.parametrize("volume,level", volumes_where_both_are_right())
def test_same_edge_vertices_as_skimage(skimage_mc, volume, level):
    spacing = (0.5, 1.25, 2.0)
    ours = cmc33.marching_cubes(volume, level, spacing=spacing)
    theirs = skimage_mc(volume, level, spacing=spacing)
    ours_edges, ours_interior = edge_vertices(ours[0], spacing)
    theirs_edges, _ = edge_vertices(theirs[0], spacing)
    assert ours_edges.keys() == theirs_edges.keys()
    difference = max(abs(ours_edges[k] - theirs_edges[k]) for k in ours_edges)
    if volume.dtype.kind in "iu":  # a half-integer level never comes within 2^-10 of an edge's end
        assert difference < 1e-5
    else:
        assert difference <= CLAMP + 1e-5
    # every vertex of ours is an edge vertex or one inside a cell that needs it
    assert len(ours_edges) + ours_interior == len(ours[0])
    # and the mesh has the topology of the trilinear level set (scikit-image's need not)
    expected = cmc33.field_topology(volume, level)
    got = cmc33.mesh_topology(ours[:2])
    assert expected.determined
    assert (got.euler, got.components, got.closed_components, got.b1, got.boundary_loops) == \
        (expected.euler, expected.b0, expected.b2, expected.b1, expected.boundary_loops)


@pytest.mark.parametrize("volume,level", volumes_where_both_are_right())
def test_same_orientation_and_values_as_skimage(skimage_mc, volume, level):
    for direction in ("descent", "ascent"):
        ours = cmc33.marching_cubes(volume, level, gradient_direction=direction)
        theirs = skimage_mc(volume, level, gradient_direction=direction)
        # faces wound alike: descent against the normals, ascent along them
        expected = 0.0 if direction == "descent" else 1.0
        assert abs(facing(*ours[:3]) - expected) < 0.02
        assert abs(facing(*theirs[:3]) - expected) < 0.02
    # the same vertex, the same normal direction and the same value
    index = {tuple(np.round(v, 4)): i for i, v in enumerate(theirs[0].astype(np.float64))}
    pairs = [(i, index[tuple(np.round(v, 4))]) for i, v in enumerate(ours[0].astype(np.float64))
             if tuple(np.round(v, 4)) in index]
    assert len(pairs) > 0.9 * len(ours[0])
    a, b = np.array(pairs).T
    dots = (ours[2][a] * theirs[2][b]).sum(axis=1)
    assert np.mean(dots > 0) > 0.99
    if volume.dtype.kind in "iu":  # values are exact for integer data
        assert np.array_equal(ours[3][a], theirs[3][b])
    else:
        assert np.allclose(ours[3][a], theirs[3][b], rtol=1e-5)


def test_signature_accepts_every_skimage_keyword(skimage_mc):
    ours = inspect.signature(cmc33.marching_cubes).parameters
    for name, p in inspect.signature(skimage_mc).parameters.items():
        assert name in ours, name
        assert ours[name].kind == p.kind, name
        if name != "method":
            assert ours[name].default == p.default, name


def test_skimage_keyword_calls_work_unchanged(skimage_mc):
    volume = ellipsoid()
    kwargs = dict(level=10.0, spacing=(1.0, 2.0, 0.5), gradient_direction="ascent", step_size=1,
                  allow_degenerate=False, method="lewiner", mask=None)
    for mc in (skimage_mc, cmc33.marching_cubes):
        verts, faces, normals, values = mc(volume, **kwargs)
        assert verts.shape[1] == 3 and faces.shape[1] == 3 and normals.shape == verts.shape
        assert values.shape == (len(verts),)


def test_a_volume_from_read_volume_is_its_samples():
    volume = cmc33.read_volume(BUCKY)
    for a, b in zip(cmc33.marching_cubes(volume, 100.5), cmc33.marching_cubes(volume.samples, 100.5)):
        assert np.array_equal(a, b)


def test_arrays_types_and_shapes():
    verts, faces, normals, values = cmc33.marching_cubes(ellipsoid(), 0.5)
    assert verts.dtype == np.float32 and normals.dtype == np.float32 and values.dtype == np.float32
    assert faces.dtype == np.int32
    for a in (verts, faces, normals, values):
        assert a.flags.c_contiguous
    assert np.allclose(np.linalg.norm(normals, axis=1), 1, atol=1e-6)
    assert faces.min() >= 0 and faces.max() < len(verts)


def test_vertices_in_the_arrays_axis_order():
    # a slab thin along axis 0: the vertices' first coordinate spans only that axis's extent
    volume = np.zeros((3, 20, 40))
    volume[1, 5:15, 10:30] = 1
    verts, _, _, _ = cmc33.marching_cubes(volume, 0.5)
    assert verts[:, 0].min() > 0 and verts[:, 0].max() < 2
    assert 4 <= verts[:, 1].min() and verts[:, 1].max() <= 15
    assert 9 <= verts[:, 2].min() and verts[:, 2].max() <= 30


def test_level_defaults_to_the_middle_of_the_data_range():
    volume = uint8_blobs()
    middle = 0.5 * (float(volume.min()) + float(volume.max()))
    for a, b in zip(cmc33.marching_cubes(volume), cmc33.marching_cubes(volume, middle)):
        assert np.array_equal(a, b)


@pytest.mark.parametrize("level", [-1.0, 256.0])
def test_level_outside_the_data_range_is_a_value_error_as_in_skimage(skimage_mc, level):
    volume = uint8_blobs()
    with pytest.raises(ValueError):
        skimage_mc(volume, level)
    with pytest.raises(ValueError, match="within volume data range"):
        cmc33.marching_cubes(volume, level)


def test_levels_at_the_ends_of_the_range_follow_the_sign_rule():
    volume = uint8_blobs()
    # a sample equal to the level counts as above: at the maximum, a surface around the maxima
    verts, faces, _, _ = cmc33.marching_cubes(volume, float(volume.max()))
    assert len(faces) > 0
    assert cmc33.mesh_topology((verts, faces)).nonmanifold_edges == 0
    # at the minimum every sample is above: nothing to extract, as scikit-image says it
    with pytest.raises(RuntimeError, match="No surface found"):
        cmc33.marching_cubes(volume, float(volume.min()))


def test_constant_volume_has_no_surface():
    with pytest.raises(RuntimeError, match="No surface found"):
        cmc33.marching_cubes(np.full((4, 4, 4), 7.0))


def test_spacing_scales_vertices_and_turns_normals():
    volume = ellipsoid()
    spacing = (0.5, 1.25, 2.0)
    unit = cmc33.marching_cubes(volume, 20.0)
    scaled = cmc33.marching_cubes(volume, 20.0, spacing=spacing)
    assert np.allclose(scaled[0], unit[0] * np.array(spacing, dtype=np.float32), rtol=1e-6, atol=1e-6)
    assert np.array_equal(scaled[1], unit[1]) and np.array_equal(scaled[3], unit[3])
    # normals of the scaled field: the index-space gradient divided by the spacing, normalised
    turned = unit[2] / np.array(spacing)
    turned /= np.linalg.norm(turned, axis=1, keepdims=True)
    assert np.allclose(scaled[2], turned, atol=1e-5)


def test_spacing_must_be_three_numbers():
    for bad in [(1.0, 1.0), (1, 2, 3, 4), "abc"]:
        with pytest.raises(ValueError):
            cmc33.marching_cubes(ellipsoid(), 0.5, spacing=bad)


def test_gradient_direction_reverses_the_winding_only():
    volume = uint8_blobs()
    descent = cmc33.marching_cubes(volume, 100.5, gradient_direction="descent")
    ascent = cmc33.marching_cubes(volume, 100.5, gradient_direction="ascent")
    assert np.array_equal(descent[0], ascent[0]) and np.array_equal(descent[2], ascent[2])
    assert np.array_equal(descent[1], ascent[1][:, [0, 2, 1]])
    with pytest.raises(ValueError, match="gradient_direction"):
        cmc33.marching_cubes(volume, 100.5, gradient_direction="up")


def test_the_native_mesh_in_the_arrays_axis_order():
    volume = ellipsoid()
    mesh = cmc33.extract(volume, 30.0, normals=True)
    verts, faces, normals, _ = cmc33.marching_cubes(volume, 30.0)
    assert np.array_equal(verts, mesh.vertices[:, ::-1]) and np.array_equal(normals, mesh.normals[:, ::-1])
    # (x, y, z) to (z, y, x) is a mirror: the native winding (counter-clockwise around the
    # normals) is clockwise in the array's order, scikit-image's 'descent'
    assert np.array_equal(faces, mesh.triangles.astype(np.int32))
    assert facing(verts, faces, normals) < 0.02


def test_step_size_reads_every_nth_sample(skimage_mc):
    volume = uint8_blobs()
    stepped = cmc33.marching_cubes(volume, 120.5, step_size=2, spacing=(1.0, 0.5, 2.0))
    subsampled = cmc33.marching_cubes(np.ascontiguousarray(volume[::2, ::2, ::2]), 120.5, spacing=(2.0, 1.0, 4.0))
    for a, b in zip(stepped, subsampled):
        assert np.array_equal(a, b)
    theirs = skimage_mc(volume, 120.5, step_size=2, spacing=(1.0, 0.5, 2.0))
    assert edge_vertices(stepped[0], (2.0, 1.0, 4.0))[0].keys() == edge_vertices(theirs[0], (2.0, 1.0, 4.0))[0].keys()
    assert np.array_equal(stepped[0], cmc33.marching_cubes(volume, 120.5, step_size=2.0, spacing=(1.0, 0.5, 2.0))[0])
    with pytest.raises(ValueError, match="step_size"):
        cmc33.marching_cubes(volume, 120.5, step_size=0)
    with pytest.raises(RuntimeError, match="No surface found"):
        cmc33.marching_cubes(volume, 120.5, step_size=100)


@pytest.mark.parametrize("dtype", [np.int8, np.uint16, np.int32, np.float32, np.float64])
@pytest.mark.parametrize("shape", [(2, 2, 2), (2, 3, 5), (7, 4, 3), (9, 11, 13)])
def test_values_are_the_largest_range_of_the_cells_using_each_vertex(dtype, shape):
    """Without a mask, emit computes values from each vertex's edge (the cells around it); with a
    mask, from the cells of its triangles. A full mask must give the same bytes, also at the
    grid's borders, on strided views and for both windings; and each value is checked against
    the cells of its triangles directly."""
    rng = np.random.default_rng(sum(shape) + np.dtype(dtype).itemsize)
    volume = rng.integers(-100, 100, size=(2 * shape[0], shape[1], shape[2] + 1)).astype(dtype)[::2, :, 1:]
    if np.dtype(dtype).kind == "f":
        volume = volume * np.asarray(0.37, dtype=dtype)
    level = float(np.median(volume)) + 0.5
    for direction in ("descent", "ascent"):
        whole = cmc33.marching_cubes(volume, level, gradient_direction=direction, threads=2)
        masked = cmc33.marching_cubes(volume, level, gradient_direction=direction,
                                      mask=np.ones(volume.shape, dtype=bool), threads=2)
        for a, b in zip(whole, masked):
            assert np.array_equal(a, b)
    verts, faces, _, values = whole
    wide = volume.astype(np.float64)
    expected = np.zeros(len(verts))
    for face in faces:
        corner = np.floor(verts[face].mean(axis=0)).astype(int)  # the cell the triangle lies in
        cell = wide[corner[0]:corner[0] + 2, corner[1]:corner[1] + 2, corner[2]:corner[2] + 2]
        expected[face] = np.maximum(expected[face], cell.max() - cell.min())
    assert np.array_equal(values, expected.astype(np.float32))


def test_mask_keeps_the_cells_skimage_keeps(skimage_mc):
    volume = uint8_blobs()
    mask = np.zeros(volume.shape, dtype=bool)
    mask[5:30, 3:25, 10:40] = True
    ours = cmc33.marching_cubes(volume, 127.5, mask=mask)
    theirs = skimage_mc(volume, 127.5, mask=mask)
    assert edge_vertices(ours[0])[0].keys() == edge_vertices(theirs[0])[0].keys()
    whole = cmc33.marching_cubes(volume, 127.5)
    assert 0 < len(ours[1]) < len(whole[1])
    # every vertex is used, the surface is an open manifold piece, still embedded
    assert np.array_equal(np.unique(ours[1]), np.arange(len(ours[0])))
    topology = cmc33.mesh_topology(ours[:2])
    assert topology.nonmanifold_edges == 0 and topology.boundary_edges > 0
    assert cmc33.mesh_geometry(ours[:2]).embedded
    # a full mask changes nothing; a mask of integers counts non-zero as True
    for a, b in zip(cmc33.marching_cubes(volume, 127.5, mask=np.ones(volume.shape, dtype=bool)), whole):
        assert np.array_equal(a, b)
    for a, b in zip(cmc33.marching_cubes(volume, 127.5, mask=mask.astype(np.int16) * 3), ours):
        assert np.array_equal(a, b)
    with pytest.raises(ValueError, match="same shape"):
        cmc33.marching_cubes(volume, 127.5, mask=mask[1:])
    with pytest.raises(RuntimeError, match="No surface found"):
        cmc33.marching_cubes(volume, 127.5, mask=np.zeros(volume.shape, dtype=bool))


def test_mask_with_step_size(skimage_mc):
    volume = uint8_blobs()
    mask = np.zeros(volume.shape, dtype=bool)
    mask[:, :20, :] = True
    ours = cmc33.marching_cubes(volume, 127.5, mask=mask, step_size=3)
    theirs = skimage_mc(volume, 127.5, mask=mask, step_size=3)
    assert edge_vertices(ours[0], (3, 3, 3))[0].keys() == edge_vertices(theirs[0], (3, 3, 3))[0].keys()


def test_allow_degenerate_is_accepted_and_there_is_nothing_to_remove():
    volume = bucky()
    a = cmc33.marching_cubes(volume, 100.0, allow_degenerate=True)
    b = cmc33.marching_cubes(volume, 100.0, allow_degenerate=False)
    for x, y in zip(a, b):
        assert np.array_equal(x, y)
    # an integer level on integer data: ties everywhere, still no degenerate triangle
    geometry = cmc33.mesh_geometry(a[:2])
    assert geometry.embedded and geometry.zero_area_triangles == 0


def test_method_names():
    volume = uint8_blobs()
    lewiner = cmc33.marching_cubes(volume, 127.5, method="lewiner")
    for a, b in zip(lewiner, cmc33.marching_cubes(volume, 127.5)):
        assert np.array_equal(a, b)
    for a, b in zip(cmc33.marching_cubes(volume, 127.5, method="lorensen"),
                    cmc33.marching_cubes(volume, 127.5, method="mc")):
        assert np.array_equal(a, b)
    cmc33.marching_cubes(volume, 127.5, method="mc33-lewiner")
    with pytest.raises(ValueError, match="method"):
        cmc33.marching_cubes(volume, 127.5, method="flying-edges")


def test_bad_volumes_are_value_errors():
    with pytest.raises(ValueError, match="3D"):
        cmc33.marching_cubes(np.zeros((4, 4)), 0.5)
    with pytest.raises(ValueError, match="2x2x2"):
        cmc33.marching_cubes(np.zeros((4, 1, 4)), 0.5)
    with pytest.raises(ValueError, match="type"):
        cmc33.marching_cubes(np.zeros((4, 4, 4), dtype=complex), 0.5)
    volume = ellipsoid()
    volume[3, 4, 5] = np.nan
    with pytest.raises(cmc33.NonFiniteError) as error:
        cmc33.marching_cubes(volume, 0.5)
    assert isinstance(error.value, ValueError) and "NaN" in str(error.value)


def test_non_finite_samples_are_named_as_the_caller_indexes_them():
    volume = ellipsoid()
    volume[3, 4, 5] = np.nan
    volume[6, 1, 2] = -np.inf
    for layout in (volume, np.asfortranarray(volume), volume.astype(np.float32)):
        with pytest.raises(cmc33.NonFiniteError, match=r"^2 samples are NaN or infinite, the first at volume\[3, 4, 5\];"):
            cmc33.marching_cubes(layout, 0.5)
    # step_size reads every other sample: [3, 4, 5] is skipped, [6, 1, 2] is not read either, [8, 2, 0] is
    volume[8, 2, 0] = np.nan
    with pytest.raises(cmc33.NonFiniteError, match=r"^1 sample is NaN or infinite, the first at volume\[8, 2, 0\];"):
        cmc33.marching_cubes(volume, 0.5, step_size=2)
    # a view with negative strides: the index is the view's, as the caller wrote it
    flipped = volume[::-1]
    with pytest.raises(cmc33.NonFiniteError, match=r"the first at volume\[21, 2, 0\];"):
        cmc33.marching_cubes(flipped, 0.5)


def test_lorensen_private_name_is_refused_not_answered_with_four_arrays():
    with pytest.raises(ValueError, match=r"'_lorensen' is scikit-image's private .* use method='lorensen'"):
        cmc33.marching_cubes(ellipsoid(), 0.5, method="_lorensen")


def test_every_method_scikit_image_has_returns_its_number_of_arrays(skimage_mc):
    volume = ellipsoid()
    for method in ("lewiner", "lorensen", "_lorensen"):
        try:
            theirs = skimage_mc(volume, 10.0, method=method)
        except ValueError:
            continue  # not a method of the installed scikit-image
        try:
            ours = cmc33.marching_cubes(volume, 10.0, method=method)
        except ValueError as e:
            assert "private" in str(e), (method, e)  # refused by name, never a different shape
            continue
        assert len(ours) == len(theirs), method
