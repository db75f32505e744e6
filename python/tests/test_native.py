"""The native API: meshes over the library's memory, frames, files byte for byte against the
command line, topology and geometry, cells, the verifier, errors and documentation."""

import gc
import inspect
import json
import subprocess
from pathlib import Path

import numpy as np
import pytest

import cmc33
from conftest import BUCKY, ellipsoid, shared_volume, uint8_blobs


# ------------------------------------------------------------------------------------------------
# Meshes

def test_mesh_arrays_share_the_librarys_memory():
    mesh = cmc33.extract(ellipsoid(), 10.0, normals=True)
    vertices, triangles, normals = mesh.vertices, mesh.triangles, mesh.normals
    for array in (vertices, triangles, normals):
        assert array.base is mesh and not array.flags.owndata
    assert vertices.dtype == np.float32 and triangles.dtype == np.uint32 and normals.dtype == np.float32
    assert vertices.shape == (mesh.vertex_count, 3) and triangles.shape == (mesh.triangle_count, 3)
    # two reads are two views of one memory: a write through one shows through the other
    vertices[0, 0] = 1234.5
    assert mesh.vertices[0, 0] == 1234.5
    assert np.shares_memory(mesh.normals, normals)


def test_mesh_arrays_keep_the_mesh_alive():
    expected = cmc33.extract(ellipsoid(), 10.0).vertices.copy()
    vertices = cmc33.extract(ellipsoid(), 10.0).vertices  # the Mesh object is gone but for this
    gc.collect()
    _ = [np.ones(len(expected) * 3, dtype=np.float32) for _ in range(10)]  # reuse freed memory if any
    assert np.array_equal(vertices, expected)


def test_normals_only_on_request_unit_and_facing_below():
    volume = ellipsoid()
    assert cmc33.extract(volume, 10.0).normals is None
    mesh = cmc33.extract(volume, 10.0, normals=True)
    assert np.allclose(np.linalg.norm(mesh.normals, axis=1), 1, atol=1e-6)
    # the field is larger inside: normals point out of the ellipsoid (x, y, z is the array reversed)
    centre = (np.array(volume.shape[::-1]) - 1) / 2
    assert np.mean(((mesh.vertices - centre) * mesh.normals).sum(axis=1) > 0) == 1.0
    # triangles wind counter-clockwise seen from where the normals point
    v = mesh.vertices.astype(np.float64)
    t = mesh.triangles.astype(np.int64)
    face = np.cross(v[t[:, 1]] - v[t[:, 0]], v[t[:, 2]] - v[t[:, 0]])
    assert np.mean((face * mesh.normals[t].sum(axis=1)).sum(axis=1) > 0) > 0.99


def test_an_empty_mesh_has_empty_arrays():
    mesh = cmc33.extract(ellipsoid(), 1000.0, normals=True)  # above every sample
    assert mesh.vertices.shape == (0, 3) and mesh.triangles.shape == (0, 3) and mesh.normals.shape == (0, 3)
    assert cmc33.mesh_topology(mesh).faces == 0


def test_mesh_from_arrays_copies_and_checks():
    verts, faces, normals, _ = cmc33.marching_cubes(ellipsoid(), 10.0)
    mesh = cmc33.Mesh(verts, faces, normals)
    assert np.array_equal(mesh.vertices, verts) and np.array_equal(mesh.triangles, faces)
    assert not np.shares_memory(mesh.vertices, verts)
    with pytest.raises(ValueError, match="expected 0 <= index"):
        cmc33.Mesh(verts, faces + len(verts))
    with pytest.raises(ValueError, match=r"expected \(V, 3\)"):
        cmc33.Mesh(verts[:, :2], faces)
    with pytest.raises(ValueError, match="integers"):
        cmc33.mesh_topology((verts, faces.astype(float)))
    with pytest.raises(ValueError, match="integers"):
        cmc33.Mesh(verts, faces.astype(float))


def test_cells_per_subcase_counts_the_crossed_cells():
    mesh = cmc33.extract(uint8_blobs(), 127.5)
    counts = mesh.cells_per_subcase
    assert set(counts) == set(cmc33.subcase_names())
    assert sum(counts.values()) > 0 and counts["0"] == 0
    assert cmc33.Mesh(mesh.vertices, mesh.triangles).cells_per_subcase is None


# ------------------------------------------------------------------------------------------------
# Frames and files

def test_read_volume_gives_the_array_and_its_frame():
    volume = cmc33.read_volume(BUCKY)
    assert volume.shape == (32, 32, 32) and volume.samples.shape == (32, 32, 32)
    assert volume.samples.dtype == np.uint8 and volume.samples.base is volume
    assert volume.spacing == (1.0, 1.0, 1.0) and volume.origin == (0.0, 0.0, 0.0)
    assert np.array_equal(volume.direction, np.eye(3))
    # extract(volume) is extract of its samples in its frame
    a = cmc33.extract(volume, 100)
    b = cmc33.extract(volume.samples, 100)
    assert a.vertices.tobytes() == b.vertices.tobytes() and a.triangles.tobytes() == b.triangles.tobytes()
    assert a.triangle_count == 11836  # the README's number for this volume


def test_frames_place_and_mirror_the_mesh(tmp_path):
    samples = uint8_blobs()
    spacing, origin = (0.5, 2.0, 1.25), (10.0, -5.0, 3.0)
    angle = 0.3  # a rotation about z composed with a mirror of y: det -1
    direction = np.array([[np.cos(angle), np.sin(angle), 0], [np.sin(angle), -np.cos(angle), 0], [0, 0, 1]])
    plain = cmc33.extract(samples, 127.5, normals=True)
    placed = cmc33.extract(samples, 127.5, spacing=spacing, origin=origin, direction=direction, normals=True)
    expected = np.asarray(origin) + (plain.vertices.astype(np.float64) * spacing) @ direction.T
    assert np.allclose(placed.vertices, expected, atol=1e-4)
    # the mirror reverses the winding, so the triangles keep facing their normals
    assert np.array_equal(placed.triangles[:, [0, 2, 1]], plain.triangles)
    v = placed.vertices.astype(np.float64)
    t = placed.triangles.astype(np.int64)
    face = np.cross(v[t[:, 1]] - v[t[:, 0]], v[t[:, 2]] - v[t[:, 0]])
    assert np.mean((face * placed.normals[t].sum(axis=1)).sum(axis=1) > 0) > 0.98
    # a volume written with that frame and read back carries it
    path = tmp_path / "framed.nrrd"
    cmc33.write_volume(samples, path, spacing=spacing, origin=origin, direction=direction)
    back = cmc33.read_volume(path)
    assert np.array_equal(back.samples, samples)
    assert np.allclose(back.spacing, spacing) and np.allclose(back.origin, origin)
    assert np.allclose(back.direction, direction)
    assert cmc33.extract(back, 127.5).vertices.tobytes() == cmc33.extract(
        samples, 127.5, spacing=back.spacing, origin=back.origin, direction=back.direction).vertices.tobytes()


def test_raw_volumes_need_dims_and_dtype(tmp_path):
    samples = uint8_blobs().astype(">u2")
    path = tmp_path / "blobs.raw"
    path.write_bytes(b"HEAD" + samples.tobytes())
    nz, ny, nx = samples.shape
    volume = cmc33.read_volume(path, dims=(nx, ny, nz), dtype=np.uint16, endian="big", header_bytes=4,
                               spacing=(1, 1, 2))
    assert np.array_equal(volume.samples, samples) and volume.spacing == (1.0, 1.0, 2.0)
    with pytest.raises(ValueError):
        cmc33.read_volume(path, dims=(nx, ny, nz), dtype=np.uint16, endian="middle")
    with pytest.raises(cmc33.TruncatedFileError) as error:
        cmc33.read_volume(path, dims=(nx, ny, nz + 1), dtype="uint16")
    assert isinstance(error.value, ValueError) and str(path) in str(error.value)


def run_cli(cli, *args):
    return subprocess.run([str(cli), *map(str, args)], check=True, capture_output=True, text=True)


@pytest.mark.parametrize("suffix,normals,ascii", [(".ply", False, False), (".ply", True, False),
                                                  (".ply", True, True), (".obj", True, False),
                                                  (".stl", False, False), (".off", False, False)])
def test_write_mesh_gives_the_command_lines_bytes(cli, tmp_path, suffix, normals, ascii):
    expected = tmp_path / ("cli" + suffix)
    got = tmp_path / ("python" + suffix)
    run_cli(cli, "extract", BUCKY, "--iso", 100, "-o", expected, *(["--normals"] if normals else []),
            *(["--ascii"] if ascii else []), "--quiet")
    mesh = cmc33.extract(cmc33.read_volume(BUCKY), 100, normals=normals)
    cmc33.write_mesh(mesh, got, ascii=ascii)
    assert got.read_bytes() == expected.read_bytes()


@pytest.mark.parametrize("name,iso", [("aneurism_256x256x256_uint8.nrrd", 80),
                                      ("CThead_256x256x113_uint16.nrrd", 1500)])
def test_real_volumes_byte_for_byte_with_the_command_line(cli, tmp_path, name, iso):
    path = shared_volume(name)
    run_cli(cli, "extract", path, "--iso", iso, "--normals", "-o", tmp_path / "cli.ply", "--quiet")
    cmc33.write_mesh(cmc33.extract(cmc33.read_volume(path), iso, normals=True, threads=1), tmp_path / "py.ply")
    assert (tmp_path / "py.ply").read_bytes() == (tmp_path / "cli.ply").read_bytes()


def test_read_mesh_round_trip(tmp_path):
    mesh = cmc33.extract(uint8_blobs(), 127.5, normals=True)
    for suffix in (".ply", ".obj", ".off"):
        cmc33.write_mesh(mesh, tmp_path / ("m" + suffix))
        back = cmc33.read_mesh(tmp_path / ("m" + suffix))
        assert np.array_equal(back.triangles, mesh.triangles)
        assert np.array_equal(back.vertices, mesh.vertices) or suffix != ".ply"
    # STL has no indices: the reader welds by position, and an embedded mesh comes back whole
    cmc33.write_mesh(mesh, tmp_path / "m.stl")
    welded = cmc33.read_mesh(tmp_path / "m.stl")
    assert welded.vertex_count == mesh.vertex_count and welded.triangle_count == mesh.triangle_count


# ------------------------------------------------------------------------------------------------
# Topology and geometry

def invariants(t):
    return t.euler, t.components, t.closed_components, t.b1, t.boundary_loops


def expected_invariants(f):
    return f.euler, f.b0, f.b2, f.b1, f.boundary_loops


def test_topology_on_random_grids_matches_the_field():
    rng = np.random.default_rng(12)
    checked = 0
    for trial in range(400):
        shape = tuple(rng.integers(2, 7, size=3))
        volume = rng.uniform(-1, 1, size=shape).astype(np.float32)
        if trial % 4 == 0:  # integer ties at the isovalue
            volume = np.round(volume * 2)
        expected = cmc33.field_topology(volume, 0.0)
        if not expected.determined:
            continue
        mesh = cmc33.extract(volume, 0.0, threads=1)
        got = cmc33.mesh_topology(mesh)
        assert invariants(got) == expected_invariants(expected), (trial, volume.tolist())
        assert got.nonmanifold_edges == 0 and got.nonmanifold_vertices == 0 and got.oriented, trial
        if got.faces:
            assert cmc33.mesh_geometry(mesh).embedded, trial
        checked += 1
    assert checked > 380


def test_the_verifiers_fields_through_the_python_api():
    for kind in ("grid", "closed", "ties"):
        for n in range(1, 60):
            volume = cmc33.random_field(kind, n, seed=7)
            assert volume.shape == (5, 5, 5)
            mesh = cmc33.extract(volume, 0.0)
            assert invariants(cmc33.mesh_topology(mesh)) == expected_invariants(cmc33.field_topology(volume, 0.0))
    assert cmc33.random_field("cell", 3).shape == (2, 2, 2)
    with pytest.raises(ValueError, match="kind"):
        cmc33.random_field("sphere", 1)


def test_mesh_geometry_of_our_mesh_and_of_a_soup():
    verts, faces, _, _ = cmc33.marching_cubes(cmc33.read_volume(BUCKY).samples, 100.0)  # integer ties
    geometry = cmc33.mesh_geometry((verts, faces))
    assert geometry.embedded and geometry.coincident_vertices == 0 and geometry.intersecting_pairs == 0
    assert invariants(geometry.welded) == invariants(cmc33.mesh_topology((verts, faces)))
    # two triangles crossing each other, and a duplicate vertex
    v = np.array([[0, 0, 0], [2, 0, 0], [0, 2, 0], [1, 1, -1], [1, 1, 1], [0.2, 0.2, 5], [0, 0, 0]], np.float32)
    f = np.array([[0, 1, 2], [3, 4, 5], [6, 1, 5]])
    soup = cmc33.mesh_geometry((v, f), examples=4)
    assert not soup.embedded and soup.intersecting_pairs >= 1 and soup.coincident_vertices == 2
    assert soup.intersection_examples[0] == (0, 1)


def test_topology_report_fields():
    t = cmc33.mesh_topology(cmc33.extract(ellipsoid(), 10.0))
    assert (t.euler, t.components, t.closed_components, t.b1, t.closed, t.oriented) == (2, 1, 1, 0, True, True)
    assert t.vertices - t.edges + t.faces == t.euler
    assert "euler=2" in repr(t)


def test_analyze_cell_agrees_with_the_command_line(cli):
    values = [-0.5, 0.2, 0.3, -0.4, 0.6, -0.1, -0.7, 0.8]
    for method in cmc33.METHODS:
        report = cmc33.analyze_cell(values, 0.0, method=method)
        cli_report = json.loads(run_cli(cli, "cell", "--json", "--method", method, "--", *values).stdout)
        assert report.config == cli_report["config"]
        assert report.base_case == cli_report["base_case"]
        assert report.subcase_name == cli_report["subcase"]
        assert [f.joined for f in report.faces] == [f["joined"] for f in cli_report["faces"]]
    report = cmc33.analyze_cell(values)
    assert report.config == sum(1 << c for c, v in enumerate(values) if v >= 0)
    assert report.interior.tested and report.mesh.triangle_count > 0
    with pytest.raises(ValueError, match="8 corner values"):
        cmc33.analyze_cell(values[:7])


def test_verify_runs_the_stress_test(tmp_path):
    calls = []
    report = cmc33.verify(cells=2000, grids=200, ties=100, methods=("cmc33", "mc"), seed=3,
                          failures_dir=tmp_path / "failures", progress=lambda *a: calls.append(a))
    cmc33_report, mc_report = report.methods
    assert cmc33_report.name == "cmc33" and cmc33_report.checked + cmc33_report.undetermined == 2300
    assert cmc33_report.mismatched == 0 and report.passed is False  # classic MC gets topology wrong
    assert mc_report.mismatched > 0 and mc_report.failures_written > 0
    assert report.fields == {"cell": 2000, "grid": 200, "closed": 0, "ties": 100}
    assert calls and calls[-1][0] == calls[-1][1] == 2300
    assert (tmp_path / "failures" / "failures.tsv").is_file()
    with pytest.raises(ValueError, match="method"):
        cmc33.verify(cells=1, methods=("fast",))


# ------------------------------------------------------------------------------------------------
# Errors and documentation

def test_errors_are_python_exceptions_with_the_librarys_message(tmp_path):
    with pytest.raises(cmc33.FileError) as error:
        cmc33.read_volume(tmp_path / "missing.nrrd")
    assert isinstance(error.value, OSError) and "missing.nrrd" in str(error.value)
    bad = tmp_path / "bad.nrrd"
    bad.write_bytes(b"NRRD0004\ntype: float\ndimension: 3\nsizes: 4 4 4\nencoding: raw\nendian: little\n\n" + bytes(10))
    with pytest.raises(cmc33.TruncatedFileError, match="bad.nrrd"):
        cmc33.read_volume(bad)
    with pytest.raises(cmc33.UnsupportedFormatError, match="extension"):
        cmc33.write_mesh(cmc33.extract(ellipsoid(), 10.0), tmp_path / "mesh.xyz")
    with pytest.raises(cmc33.InvalidArgumentError, match="at least 2"):
        cmc33.extract(np.zeros((1, 4, 4)), 0.5)
    with pytest.raises(cmc33.NonFiniteError, match="isovalue"):
        cmc33.extract(ellipsoid(), float("nan"))
    with pytest.raises(ValueError, match="method"):
        cmc33.extract(ellipsoid(), 1.0, method="marching")
    with pytest.raises(ValueError, match="expected 3"):
        cmc33.extract(ellipsoid(), 1.0, spacing=(1, 1))
    with pytest.raises(ValueError, match="degenerate"):
        cmc33.extract(ellipsoid(), 1.0, spacing=(1, 0, 1))
    for error_class in (cmc33.InvalidArgumentError, cmc33.FileError, cmc33.TooLargeError, cmc33.CancelledError):
        assert issubclass(error_class, cmc33.Error)
    assert issubclass(cmc33.TooLargeError, MemoryError)


def test_every_public_name_is_documented():
    for name in cmc33.__all__:
        obj = getattr(cmc33, name)
        if isinstance(obj, (tuple, list)):
            continue
        assert inspect.getdoc(obj), name
        if inspect.isfunction(obj):
            hints = inspect.signature(obj)
            assert hints.return_annotation is not inspect.Signature.empty, name
    assert len(inspect.getdoc(cmc33.marching_cubes)) > 2000
    package = Path(cmc33.__file__).parent
    assert (package / "_cmc33.pyi").is_file() and (package / "py.typed").is_file()


def test_non_finite_samples_are_named_as_numpy_indexes_them():
    volume = ellipsoid()
    volume[7, 2, 9] = np.nan
    with pytest.raises(cmc33.NonFiniteError, match=r"^1 sample is NaN or infinite, the first at volume\[7, 2, 9\];"):
        cmc33.extract(volume, 10.0)
    with pytest.raises(cmc33.NonFiniteError, match=r"the first at volume\[7, 2, 9\];"):
        cmc33.field_topology(volume, 10.0)
    wrapped = cmc33.Volume(volume, (1, 1, 1), (0, 0, 0), ((1, 0, 0), (0, 1, 0), (0, 0, 1)))
    with pytest.raises(cmc33.NonFiniteError, match=r"the first at volume.samples\[7, 2, 9\];"):
        cmc33.extract(wrapped, 10.0)
    # an error about something else keeps its own message
    with pytest.raises(cmc33.NonFiniteError, match="isovalue"):
        cmc33.extract(ellipsoid(), float("inf"))
