"""cmc33.label_surfaces: the command line's meshes, two labels as extract's level set, arrays in
place in every layout, the selection, and bad input."""

import subprocess
import threading
import time

import numpy as np
import pytest

import cmc33
from conftest import uint8_blobs


def three_classes(shape=(30, 34, 38), dtype=np.uint8):
    """Tissue-like classes of smooth data: 0 below 90, 1 to 170, 2 above; a z-slab of label 7."""
    blobs = uint8_blobs(shape)
    labels = np.digitize(blobs, [90, 170]).astype(dtype)
    labels[: shape[0] // 5] = 7
    return labels


def sorted_rows(a):
    a = np.asarray(a)
    return a[np.lexsort(a.T[::-1])]


def test_label_surfaces_are_the_command_lines(cli, tmp_path):
    labels = three_classes()
    path = tmp_path / "seg.nrrd"
    frame = dict(spacing=(0.5, 0.75, 1.25), origin=(10, -20, 5))
    cmc33.write_volume(labels, path, **frame)
    subprocess.run([str(cli), "labels", str(path), "-o", str(tmp_path / "out"), "--normals"], check=True,
                   capture_output=True)
    result = cmc33.label_surfaces(labels, normals=True, **frame)
    assert result.present == (0, 1, 2, 7) and result.selected == (1, 2, 7)
    assert set(result.surfaces) == {1, 2, 7}
    for label, mesh in result.surfaces.items():
        theirs = cmc33.read_mesh(tmp_path / "out" / f"label_{label}.ply")
        assert np.array_equal(mesh.vertices, theirs.vertices), label
        assert np.array_equal(mesh.triangles, theirs.triangles), label
        assert np.array_equal(mesh.normals, theirs.normals), label
    # a Volume read from the file gives the same, in its frame
    again = cmc33.label_surfaces(cmc33.read_volume(path), normals=True)
    assert np.array_equal(again.interfaces.vertices, result.interfaces.vertices)
    assert np.array_equal(again.interfaces.triangles, result.interfaces.triangles)


def test_interfaces_carry_both_labels_and_every_surface_is_closed():
    result = cmc33.label_surfaces(three_classes())
    n = result.interfaces.triangle_count
    assert result.front.shape == (n,) and result.behind.shape == (n,) and result.front.dtype == np.int64
    assert np.all(result.front != result.behind)
    assert set(np.unique(np.concatenate([result.front, result.behind]))) <= set(result.present)
    assert result.cells_two_labels > 0 and result.cells_many_labels > 0
    assert 0 <= result.cells_with_core <= result.cells_many_labels
    for label, mesh in result.surfaces.items():
        # each triangle with the label on a side, once
        assert mesh.triangle_count == np.count_nonzero((result.front == label) | (result.behind == label))
        assert cmc33.mesh_geometry(mesh).embedded, label
        topology = cmc33.mesh_topology(mesh)
        assert topology.oriented and topology.nonmanifold_edges == 0 and topology.nonmanifold_vertices == 0, label


def test_a_label_of_two_pieces_in_a_cell_takes_its_core():
    # label 1 on the opposite corners (0, 0, 0) and (1, 1, 1) of one cell: two pieces on its surface
    labels = np.array([1, 2, 2, 3, 2, 3, 3, 1], dtype=np.uint8).reshape(2, 2, 2)
    result = cmc33.label_surfaces(labels)
    assert (result.cells_many_labels, result.cells_with_core) == (1, 1)
    for label, mesh in result.surfaces.items():
        topology = cmc33.mesh_topology(mesh)
        assert topology.nonmanifold_edges == 0 and topology.nonmanifold_vertices == 0, label
        assert topology.components == 1, label


def test_two_labels_are_extracts_level_set():
    blobs = uint8_blobs()
    labels = (blobs >= 128).astype(np.uint8)
    result = cmc33.label_surfaces(labels)
    surface = result.surfaces[1]
    # ties (a face's saddle at 0.5) go to the lower label: the level set of label 0's indicator
    level_set = cmc33.extract((labels == 0).astype(np.float32), 0.5)
    assert surface.triangle_count == level_set.triangle_count
    assert np.array_equal(sorted_rows(surface.vertices), sorted_rows(level_set.vertices))
    ours, theirs = cmc33.mesh_topology(surface), cmc33.mesh_topology(level_set)
    assert (ours.euler, ours.components, ours.b1) == (theirs.euler, theirs.components, theirs.b1)


def test_every_layout_and_integer_type_gives_the_same_meshes():
    labels = three_classes()
    reference = cmc33.label_surfaces(labels, surfaces=False)
    assert reference.surfaces is None
    layouts = {
        "fortran": np.asfortranarray(labels),
        "int16": labels.astype(np.int16),
        "uint32": labels.astype(np.uint32),
        "int64 (converted)": labels.astype(np.int64),
        "uint64 (converted)": labels.astype(np.uint64),
    }
    for name, array in layouts.items():
        got = cmc33.label_surfaces(array, surfaces=False)
        assert np.array_equal(got.interfaces.vertices, reference.interfaces.vertices), name
        assert np.array_equal(got.interfaces.triangles, reference.interfaces.triangles), name
        assert np.array_equal(got.front, reference.front) and np.array_equal(got.behind, reference.behind), name
    # a strided view is read in place: the same as its copy
    view = labels[::-1, 1:-1, ::2]
    got = cmc33.label_surfaces(view, surfaces=False)
    copy = cmc33.label_surfaces(np.ascontiguousarray(view), surfaces=False)
    assert np.array_equal(got.interfaces.vertices, copy.interfaces.vertices)
    assert np.array_equal(got.interfaces.triangles, copy.interfaces.triangles)
    # bool is a two-label map
    mask = labels == 1
    assert cmc33.label_surfaces(mask).selected == (1,)
    # the thread count changes nothing
    one = cmc33.label_surfaces(labels, threads=1, surfaces=False)
    assert np.array_equal(one.interfaces.triangles, reference.interfaces.triangles)


def test_selection_and_background():
    labels = three_classes()
    every = cmc33.label_surfaces(labels)
    for select in ("2", 2, [2], [(2, 2)], np.int64(2)):
        got = cmc33.label_surfaces(labels, select=select)
        assert got.selected == (2,) and set(got.surfaces) == {2}, select
        assert np.array_equal(got.surfaces[2].triangles, every.surfaces[2].triangles), select
    assert cmc33.label_surfaces(labels, select="1-2,7").selected == (1, 2, 7)
    assert cmc33.label_surfaces(labels, select=[(1, 2), 7]).selected == (1, 2, 7)
    # label 7 as the background: 0 gets a surface, 7 none
    assert cmc33.label_surfaces(labels, background=7).selected == (0, 1, 2)


def test_normals_are_unit_and_point_out_of_each_label():
    result = cmc33.label_surfaces(three_classes(), normals=True)
    for label, mesh in result.surfaces.items():
        lengths = np.linalg.norm(mesh.normals, axis=1)
        assert np.allclose(lengths, 1, atol=1e-5), label
        # against the triangles' own normals (counter-clockwise: out of the label)
        v, t = mesh.vertices.astype(np.float64), mesh.triangles
        faces = np.cross(v[t[:, 1]] - v[t[:, 0]], v[t[:, 2]] - v[t[:, 0]])
        summed = np.zeros_like(v)
        for k in range(3):
            np.add.at(summed, t[:, k], faces)
        # (but where they cancel: a label meeting itself at a cell's centre, docs/labels.md)
        defined = np.linalg.norm(summed, axis=1) > 1e-9
        assert np.all(np.einsum("ij,ij->i", summed, mesh.normals)[defined] > 0), label
    assert cmc33.label_surfaces(three_classes()).interfaces.normals is None


@pytest.mark.parametrize("labels, message", [
    (np.zeros((4, 4, 4), np.float32), "integer samples"),
    (np.zeros((4, 4), np.uint8), "3D array"),
    (np.full((3, 3, 3), 2**40, np.int64), "int32 or uint32"),
])
def test_bad_label_maps_are_refused(labels, message):
    with pytest.raises(ValueError, match=message):
        cmc33.label_surfaces(labels)


@pytest.mark.parametrize("select, message", [
    ("1-", "labels"), ([(3, 1)], "ends before it starts"), ([], "empty"), ([1.5], "neither"), (object(), "expected"),
])
def test_bad_selections_are_refused(select, message):
    with pytest.raises(ValueError, match=message):
        cmc33.label_surfaces(three_classes(), select=select)


def test_the_gil_is_released_while_the_library_works():
    # work long enough to tell on a fast machine too: larger label maps until a run takes 0.3 s
    for copies in (3, 4, 5, 6, 8):
        labels = np.tile(three_classes(), (copies, copies, copies))
        done = threading.Event()
        result = {}

        def work():
            start = time.perf_counter()
            result["surfaces"] = cmc33.label_surfaces(labels, threads=1)
            result["seconds"] = time.perf_counter() - start
            done.set()

        worker = threading.Thread(target=work)
        worker.start()
        largest_gap, last = 0.0, time.perf_counter()
        while not done.is_set():
            now = time.perf_counter()
            largest_gap, last = max(largest_gap, now - last), now
        worker.join()
        if result["seconds"] > 0.3:
            break
    assert result["surfaces"].interfaces.triangle_count > 0
    assert result["seconds"] > 0.3, "the work was too short to tell"
    # with the GIL held this thread would have stood still for the whole run
    assert largest_gap < min(0.25, result["seconds"] / 2), (largest_gap, result["seconds"])


def filtered_indicator(labels, label, sigma):
    """The indicator of `label` filtered as docs/labels.md says: Gaussian taps to ceil(3 sigma),
    renormalised to the samples inside the array, along each axis in turn (written here with numpy)."""
    r = int(np.ceil(3 * sigma))
    taps = np.exp(-0.5 * (np.arange(-r, r + 1) / sigma) ** 2)
    f = (labels == label).astype(np.float64)
    for axis in range(3):
        ones = np.ones(f.shape[axis])
        weights = np.convolve(ones, taps, mode="same")
        f = np.apply_along_axis(lambda line: np.convolve(line, taps, mode="same"), axis, f)
        shape = [1, 1, 1]
        shape[axis] = -1
        f = f / weights.reshape(shape)
    return f.astype(np.float32)


def test_smooth_labels_are_the_command_lines_and_the_filtered_level_set(cli, tmp_path):
    labels = three_classes()
    path = tmp_path / "seg.nrrd"
    cmc33.write_volume(labels, path)
    subprocess.run([str(cli), "labels", str(path), "-o", str(tmp_path / "out"), "--smooth", "1.5"], check=True,
                   capture_output=True)
    result = cmc33.label_surfaces(labels, smooth=1.5)
    plain = cmc33.label_surfaces(labels)
    for label, mesh in result.surfaces.items():
        theirs = cmc33.read_mesh(tmp_path / "out" / f"label_{label}.ply")
        assert np.array_equal(mesh.vertices, theirs.vertices), label
        assert np.array_equal(mesh.triangles, theirs.triangles), label
        assert cmc33.mesh_geometry(mesh).embedded, label
        assert not np.array_equal(mesh.vertices, plain.surfaces[label].vertices), label
    # two labels: the interface is the level set 0.5 of the lower label's filtered indicator
    two = (uint8_blobs((24, 26, 28)) > 128).astype(np.uint8)
    f = filtered_indicator(two, 0, 1.2)
    assert np.abs(f - 0.5).min() > 1e-5  # no sample within rounding of the tie
    surface = cmc33.label_surfaces(two, smooth=1.2, background=1).surfaces[0]
    want = cmc33.field_topology(f, 0.5)
    got = cmc33.mesh_topology(surface)
    assert want.determined
    assert (got.euler, got.components, got.b1, got.closed_components, got.boundary_loops) == \
        (want.euler, want.b0, want.b1, want.b2, want.boundary_loops)
    assert len(surface.triangles) == len(cmc33.extract(f, 0.5).triangles)


@pytest.mark.parametrize("smooth, message", [(-1, "smooth"), (float("nan"), "smooth"), ("1", "smooth"), (True, "smooth")])
def test_bad_smooth_is_refused(smooth, message):
    with pytest.raises(ValueError, match=message):
        cmc33.label_surfaces(three_classes(), smooth=smooth)
