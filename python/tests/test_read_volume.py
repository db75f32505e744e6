"""cmc33.read_volume on the formats of issue #38, against the libraries that wrote the files:
nibabel (NIfTI, an oblique sform that differs from the qform), numpy (.npy), VTK (.vti with a
Direction), tifffile (TIFF) and pydicom (DICOM, when the package was built with GDCM). The samples
must be the writer's array, the affine the writer's own, and a mesh of the Volume the command
line's mesh of the same file, byte for byte."""

import subprocess
import sys

import numpy as np
import pytest

import cmc33
from conftest import REPO

LPS = np.diag([-1.0, -1.0, 1.0, 1.0])  # RAS <-> LPS: x and y negated


def run_cli(cli, *args):
    return subprocess.run([str(cli), *map(str, args)], check=True, capture_output=True, text=True)


def ball(shape=(9, 11, 13), seed=5):
    """A smooth field (nz, ny, nx) with a closed surface near 0 and some detail."""
    rng = np.random.default_rng(seed)
    z, y, x = np.meshgrid(*[np.linspace(-1, 1, n) for n in shape], indexing="ij")
    return (0.8 - np.sqrt(x * x + 1.2 * y * y + 0.9 * z * z) + 0.05 * rng.standard_normal(shape))


def same_mesh_as_cli(cli, tmp_path, path, volume, iso, *options):
    """extract(volume) written by the package is the command line's file for `path`, byte for byte."""
    run_cli(cli, "extract", path, "--iso", iso, "-o", tmp_path / "cli.ply", "--quiet", *options)
    mesh = cmc33.extract(volume, iso, threads=1)
    cmc33.write_mesh(mesh, tmp_path / "py.ply")
    assert mesh.triangle_count > 0
    assert (tmp_path / "py.ply").read_bytes() == (tmp_path / "cli.ply").read_bytes()
    return mesh


def in_world(volume_samples, iso, affine):
    """The mesh of the samples in index space, mapped to world by `affine` (the writer's)."""
    mesh = cmc33.extract(volume_samples, iso, threads=1)
    v = mesh.vertices.astype(np.float64)
    return v @ np.asarray(affine)[:3, :3].T + np.asarray(affine)[:3, 3], mesh.triangles


def assert_world_mesh(mesh, samples, iso, affine):
    want, triangles = in_world(samples, iso, affine)
    if np.linalg.det(np.asarray(affine)[:3, :3]) < 0:
        triangles = triangles[:, [0, 2, 1]]  # a mirroring frame reverses the winding (docs/conventions.md)
    assert np.array_equal(mesh.triangles, triangles)
    scale = max(1.0, float(np.abs(want).max()))
    assert np.abs(mesh.vertices - want).max() <= 4e-6 * scale


# ------------------------------------------------------------------------------------------------
# NIfTI (nibabel)

@pytest.fixture(scope="module")
def nib():
    return pytest.importorskip("nibabel", reason="nibabel (Debian python3-nibabel)")


def oblique_affine():
    theta, phi = 0.35, -0.2
    rz = np.array([[np.cos(theta), -np.sin(theta), 0], [np.sin(theta), np.cos(theta), 0], [0, 0, 1]])
    rx = np.array([[1, 0, 0], [0, np.cos(phi), -np.sin(phi)], [0, np.sin(phi), np.cos(phi)]])
    affine = np.eye(4)
    affine[:3, :3] = rz @ rx @ np.diag([0.9, 1.1, 2.5])
    affine[:3, 3] = (-12.25, 30.5, 7.0)
    return affine


@pytest.mark.parametrize("suffix", [".nii", ".nii.gz"])
def test_nifti_oblique_sform(nib, cli, tmp_path, suffix):
    samples = ball()                        # (nz, ny, nx) as cmc33 holds it
    data = samples.T.astype(np.float32)     # nibabel's (i, j, k) = (x, y, z)
    img = nib.Nifti1Image(data, oblique_affine())
    img.set_qform(np.diag([2.0, 3.0, 4.0, 1.0]), code=1)  # a qform that is not the sform: the sform wins
    img.set_sform(oblique_affine(), code=2)
    path = tmp_path / ("oblique" + suffix)
    nib.save(img, path)
    back = nib.load(path)

    volume = cmc33.read_volume(path)
    assert volume.samples.shape == samples.shape
    assert np.array_equal(volume.samples, np.asarray(back.dataobj).T)
    assert np.allclose(volume.affine, back.affine, rtol=0, atol=1e-12)
    assert volume.space_code == "RAS" and volume.space == "right-anterior-superior"
    assert volume.frame_source.startswith("sform")
    mesh = same_mesh_as_cli(cli, tmp_path, path, volume, 0.0)
    assert_world_mesh(mesh, volume.samples, 0.0, back.affine)

    lps = cmc33.read_volume(path, space="lps")
    assert lps.space_code == "LPS"
    assert np.allclose(lps.affine, LPS @ back.affine, rtol=0, atol=1e-12)
    mesh = same_mesh_as_cli(cli, tmp_path, path, lps, 0.0, "--space", "lps")
    assert_world_mesh(mesh, volume.samples, 0.0, LPS @ back.affine)
    # ras on a RAS file changes nothing
    assert np.array_equal(cmc33.read_volume(path, space="RAS").affine, volume.affine)


def test_nifti_qform_scaled_and_4d(nib, tmp_path):
    samples = np.round(ball() * 1000).astype(np.int16)
    img = nib.Nifti1Image(samples.T, None)
    img.set_qform(oblique_affine(), code=1)
    img.set_sform(None, code=0)
    img.header.set_slope_inter(0.5, -3.0)
    nib.save(img, tmp_path / "q.nii")
    back = nib.load(tmp_path / "q.nii")
    volume = cmc33.read_volume(tmp_path / "q.nii")
    assert volume.frame_source.startswith("qform")
    assert np.allclose(volume.affine, back.affine, rtol=0, atol=1e-6)
    assert volume.samples.dtype == np.float32
    assert np.array_equal(volume.samples, back.get_fdata(dtype=np.float32).T)

    frames = np.stack([ball(seed=s).astype(np.float32).T for s in range(3)], axis=-1)  # (x, y, z, t)
    nib.save(nib.Nifti1Image(frames, oblique_affine()), tmp_path / "t.nii")
    for n in range(3):
        assert np.array_equal(cmc33.read_volume(tmp_path / "t.nii", frame=n).samples, frames[..., n].T)
    with pytest.raises(cmc33.InvalidArgumentError, match=r"t.nii: holds 3 frames.*frame=N, 0 to 2"):
        cmc33.read_volume(tmp_path / "t.nii")
    with pytest.raises(ValueError, match="frame"):
        cmc33.read_volume(tmp_path / "t.nii", frame=-1)


def test_nifti_without_orientation_refuses_a_space(nib, tmp_path):
    img = nib.Nifti1Image(ball().astype(np.float32).T, np.diag([1.5, 2.0, 2.5, 1.0]))
    img.set_qform(None, code=0)  # neither transform: pixdim only (nibabel keeps the zooms)
    img.set_sform(None, code=0)
    nib.save(img, tmp_path / "plain.nii")
    volume = cmc33.read_volume(tmp_path / "plain.nii")
    assert volume.space_code is None and volume.frame_source.startswith("pixdim")
    assert np.allclose(volume.affine, np.diag([1.5, 2.0, 2.5, 1.0]))
    with pytest.raises(cmc33.InvalidArgumentError, match="plain.nii: .*no anatomical space"):
        cmc33.read_volume(tmp_path / "plain.nii", space="lps")
    with pytest.raises(ValueError, match="'ras' or 'lps'"):
        cmc33.read_volume(tmp_path / "plain.nii", space="xyz")
    with pytest.raises(cmc33.InvalidArgumentError):  # NIfTI gives its own frame
        cmc33.read_volume(tmp_path / "plain.nii", spacing=(1, 1, 1))


# ------------------------------------------------------------------------------------------------
# .npy (numpy)

@pytest.mark.parametrize("order", ["C", "F"])
@pytest.mark.parametrize("dtype", ["<f4", ">f8", "<i2", "u1", "<u4"])
def test_npy_is_the_array(tmp_path, order, dtype):
    samples = np.round(ball() * 100).astype(dtype) if np.dtype(dtype).kind != "f" else ball().astype(dtype)
    np.save(tmp_path / "a.npy", np.asarray(samples, order=order))
    volume = cmc33.read_volume(tmp_path / "a.npy")
    assert volume.shape == samples.shape
    assert np.array_equal(volume.samples, samples)
    assert volume.samples.dtype == samples.dtype.newbyteorder("=")
    assert np.array_equal(volume.affine, np.eye(4))
    assert volume.space_code is None


def test_npy_frame_spacing_origin(cli, tmp_path):
    stack = np.stack([ball(seed=s) for s in range(3)]).astype(np.float32)  # (t, z, y, x)
    np.save(tmp_path / "s.npy", stack)
    volume = cmc33.read_volume(tmp_path / "s.npy", frame=2, spacing=(0.5, 0.25, 2.0), origin=(1, -2, 3))
    assert np.array_equal(volume.samples, stack[2])
    assert np.array_equal(volume.affine, [[0.5, 0, 0, 1], [0, 0.25, 0, -2], [0, 0, 2, 3], [0, 0, 0, 1]])
    same_mesh_as_cli(cli, tmp_path, tmp_path / "s.npy", volume, 0.0, "--frame", 2, "--spacing", 0.5, 0.25, 2,
                     "--origin", 1, -2, 3)
    with pytest.raises(cmc33.InvalidArgumentError, match="no anatomical space"):
        cmc33.read_volume(tmp_path / "s.npy", frame=0, space="ras")


def test_npy_zero_copy(tmp_path):
    np.save(tmp_path / "z.npy", ball().astype(np.float32))
    volume = cmc33.read_volume(tmp_path / "z.npy")
    samples = volume.samples
    assert not samples.flags.owndata and samples.base is not None
    assert samples.__array_interface__["data"][0] == volume.samples.__array_interface__["data"][0]


# ------------------------------------------------------------------------------------------------
# .vti (VTK)

def test_vti_with_direction(cli, tmp_path):
    vtk = pytest.importorskip("vtk", reason="VTK (Debian python3-vtk9)")
    from vtk.util import numpy_support
    samples = ball().astype(np.float32)
    nz, ny, nx = samples.shape
    theta = 0.4
    direction = np.array([[np.cos(theta), 0, np.sin(theta)], [0, 1, 0], [-np.sin(theta), 0, np.cos(theta)]]) @ np.diag([1, -1, 1])
    img = vtk.vtkImageData()
    img.SetDimensions(nx, ny, nz)
    img.SetOrigin(3.5, -2.0, 11.0)
    img.SetSpacing(0.7, 1.3, 2.1)
    img.SetDirectionMatrix(*direction.flatten())
    for name, values in (("density", samples), ("other", -samples)):
        array = numpy_support.numpy_to_vtk(values.ravel(), deep=True)  # C order of (z, y, x): x fastest, as VTK
        array.SetName(name)
        img.GetPointData().AddArray(array)
    img.GetPointData().SetActiveScalars("density")
    writer = vtk.vtkXMLImageDataWriter()
    writer.SetFileName(str(tmp_path / "i.vti"))
    writer.SetInputData(img)
    writer.SetCompressorTypeToZLib()
    writer.Write()

    index_to_world = np.array([[img.GetIndexToPhysicalMatrix().GetElement(r, c) for c in range(4)] for r in range(4)])
    volume = cmc33.read_volume(tmp_path / "i.vti")
    assert np.array_equal(volume.samples, samples)
    assert np.allclose(volume.affine, index_to_world, rtol=0, atol=1e-12)
    assert volume.frame_source.startswith("Origin, Spacing, Direction") and volume.space_code is None
    mesh = same_mesh_as_cli(cli, tmp_path, tmp_path / "i.vti", volume, 0.0)
    assert_world_mesh(mesh, samples, 0.0, index_to_world)
    assert np.array_equal(cmc33.read_volume(tmp_path / "i.vti", array="other").samples, -samples)
    with pytest.raises(ValueError, match="nothing"):
        cmc33.read_volume(tmp_path / "i.vti", array="nothing")


# ------------------------------------------------------------------------------------------------
# TIFF (tifffile)

def test_tiff_stack(cli, tmp_path):
    tifffile = pytest.importorskip("tifffile", reason="tifffile (Debian python3-tifffile)")
    samples = np.round((ball() + 1) * 1000).astype(np.uint16)
    tifffile.imwrite(tmp_path / "s.tif", samples, imagej=True, resolution=(1 / 0.4, 1 / 0.4),
                     metadata={"axes": "ZYX", "spacing": 1.5, "unit": "um"})
    try:
        volume = cmc33.read_volume(tmp_path / "s.tif")
    except cmc33.UnsupportedFormatError as e:
        if "no TIFF reader" not in str(e):
            raise
        pytest.skip("this build of the package has no TIFF reader (libtiff)")
    assert np.array_equal(volume.samples, samples)
    assert np.allclose(volume.affine, np.diag([0.4, 0.4, 1.5, 1.0]))
    same_mesh_as_cli(cli, tmp_path, tmp_path / "s.tif", volume, 1000.5)
    given = cmc33.read_volume(tmp_path / "s.tif", spacing=(1, 2, 3), origin=(4, 5, 6))
    assert np.array_equal(given.affine, [[1, 0, 0, 4], [0, 2, 0, 5], [0, 0, 3, 6], [0, 0, 0, 1]])


# ------------------------------------------------------------------------------------------------
# DICOM (pydicom), when the package has a DICOM reader

def test_dicom_oblique_rescaled_series(cli, tmp_path):
    pytest.importorskip("pydicom", reason="pydicom (Debian python3-pydicom)")
    sys.path.insert(0, str(REPO / "tests" / "io"))
    try:
        import write_dicom
    finally:
        sys.path.pop(0)
    r = write_dicom.rotation(0.3, -0.2, 0.5)
    stored = write_dicom.field(9, 7, 6)
    write_dicom.write_series(str(tmp_path / "ct"), stored, (-20.5, 13.25, 101.0), r[:, 0], r[:, 1], 1.25 * r[:, 2],
                             (0.9, 0.6), slope=1, intercept=-1024)
    write_dicom.expected(str(tmp_path / "ct"), str(tmp_path / "ct.json"))
    try:
        volume = cmc33.read_volume(tmp_path / "ct")
    except cmc33.UnsupportedFormatError as e:
        assert "no DICOM reader" in str(e)
        pytest.skip("this build of the package has no DICOM reader (-DCMC33_WITH_GDCM=ON)")
    import json
    want = json.loads((tmp_path / "ct.json").read_text())
    affine = np.eye(4)
    affine[:3, :3] = np.array(want["axes"]).T
    affine[:3, 3] = want["origin"]
    assert volume.space_code == "LPS"
    assert np.allclose(volume.affine, affine, rtol=0, atol=1e-5)
    assert np.array_equal(volume.samples.ravel(), np.array(want["values"]).astype(volume.samples.dtype))
    iso = float(np.median(volume.samples)) + 0.5
    same_mesh_as_cli(cli, tmp_path, tmp_path / "ct", volume, iso)
    ras = cmc33.read_volume(tmp_path / "ct", space="ras")
    assert np.allclose(ras.affine, LPS @ affine, rtol=0, atol=1e-5)


# ------------------------------------------------------------------------------------------------
# The frame of Volumes made from arrays, and the arguments

def test_affine_of_a_volume_made_here():
    direction = np.array([[0, -1, 0], [1, 0, 0], [0, 0, 1]], dtype=float)
    volume = cmc33.Volume(np.zeros((2, 3, 4), np.float32), (1.0, 2.0, 3.0), (5.0, 6.0, 7.0), direction)
    assert np.array_equal(volume.affine, [[0, -2, 0, 5], [1, 0, 0, 6], [0, 0, 3, 7], [0, 0, 0, 1]])
    assert volume.space_code is None and volume.frame_source == ""


def test_space_codes_of_named_spaces(tmp_path):
    for space, code in (("left-posterior-superior", "LPS"), ("right-anterior-superior", "RAS"),
                        ("scanner-xyz", None)):
        (tmp_path / "v.nrrd").write_bytes(
            f"NRRD0004\ntype: uint8\ndimension: 3\nsizes: 2 2 2\nspace: {space}\n"
            "space directions: (1,0,0) (0,1,0) (0,0,1)\nencoding: raw\n\n".encode() + bytes(8))
        assert cmc33.read_volume(tmp_path / "v.nrrd").space_code == code


def test_bad_arguments(tmp_path):
    path = tmp_path / "a.npy"
    np.save(path, ball())
    with pytest.raises(ValueError, match="dtype is for headerless raw files"):
        cmc33.read_volume(path, dtype=np.float32)
    with pytest.raises(ValueError, match="array"):
        cmc33.read_volume(path, array="")
    with pytest.raises(ValueError, match="origin is for"):
        cmc33.read_volume(tmp_path / "x.raw", dims=(2, 2, 2), dtype="uint8", origin=(1, 2, 3))


@pytest.mark.parametrize("suffix", [".hdr", ".hdr.gz"])
def test_nifti_pairs(nib, cli, tmp_path, suffix):
    """A .hdr/.img pair, and a compressed .hdr.gz/.img.gz pair, as nibabel writes them."""
    samples = ball().astype(np.float32)
    nib.save(nib.Nifti1Pair(samples.T, oblique_affine()), tmp_path / ("pair" + suffix))
    back = nib.load(tmp_path / ("pair" + suffix))
    volume = cmc33.read_volume(tmp_path / ("pair" + suffix))
    assert np.array_equal(volume.samples, np.asarray(back.dataobj).T)
    assert np.allclose(volume.affine, back.affine, rtol=0, atol=1e-12)
    same_mesh_as_cli(cli, tmp_path, tmp_path / ("pair" + suffix), volume, 0.0)
