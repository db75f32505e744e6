"""cmc33.vtk.ExtractFilter against cmc33.extract: on vtkImageData with an oblique direction, an
extent that does not start at 0, and a mirrored frame, the filter's points are extract's vertices
(index frame) mapped through the image's GetIndexToPhysicalMatrix(), to float precision, with the
same triangles (reversed in a mirrored frame); its field data states the mesh's topology.
Exit 77 when VTK's Python bindings are not installed."""

import sys

import numpy as np

import package_path


def field(shape, seed):
    """A smooth field with many components and handles: a sum of random Gaussians."""
    rng = np.random.default_rng(seed)
    z, y, x = np.meshgrid(*(np.linspace(0, 1, n) for n in shape), indexing="ij")
    f = np.zeros(shape)
    for _ in range(12):
        c, w = rng.random(3), 0.05 + 0.1 * rng.random()
        f += np.exp(-((x - c[0]) ** 2 + (y - c[1]) ** 2 + (z - c[2]) ** 2) / (2 * w * w))
    return f.astype(np.float32)


def rotation(axis, angle):
    a = np.asarray(axis, dtype=float) / np.linalg.norm(axis)
    k = np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])
    return np.eye(3) + np.sin(angle) * k + (1 - np.cos(angle)) * k @ k


def image_of(samples, spacing, origin, direction, first):
    from vtkmodules.util import numpy_support
    from vtkmodules.vtkCommonDataModel import vtkImageData
    nz, ny, nx = samples.shape
    image = vtkImageData()
    image.SetExtent(first[0], first[0] + nx - 1, first[1], first[1] + ny - 1, first[2], first[2] + nz - 1)
    image.SetSpacing(*spacing)
    image.SetOrigin(*origin)
    image.SetDirectionMatrix(*np.asarray(direction, dtype=float).reshape(9))
    values = numpy_support.numpy_to_vtk(samples.reshape(-1), deep=1)
    values.SetName("density")
    image.GetPointData().SetScalars(values)
    return image


def physical(image, index_vertices, first):
    m = np.array([[image.GetIndexToPhysicalMatrix().GetElement(r, c) for c in range(4)] for r in range(4)])
    ijk = index_vertices.astype(np.float64) + np.asarray(first, dtype=float)
    return ijk @ m[:3, :3].T + m[:3, 3]


def polydata_arrays(poly):
    from vtkmodules.util import numpy_support
    points = numpy_support.vtk_to_numpy(poly.GetPoints().GetData()).astype(np.float64)
    conn = numpy_support.vtk_to_numpy(poly.GetPolys().GetConnectivityArray())
    offsets = numpy_support.vtk_to_numpy(poly.GetPolys().GetOffsetsArray())
    assert np.all(np.diff(offsets) == 3), "every cell is a triangle"
    return points, conn.reshape(-1, 3)


def check(name, ok, detail=""):
    print(f"{'ok  ' if ok else 'FAIL'} {name}{': ' + detail if detail else ''}")
    return ok


def main():
    args = package_path.arguments(__doc__).parse_args()
    package_path.setup(args)
    try:
        import vtkmodules.vtkCommonDataModel  # noqa: F401 - is VTK there?
    except ImportError as e:
        package_path.skip(f"VTK's Python bindings are not installed ({e}; Debian: python3-vtk9)")
    import cmc33
    from vtkmodules.util import numpy_support
    from cmc33.vtk import ExtractFilter, image_to_samples, samples_to_image

    ok = True
    samples = field((19, 23, 29), seed=7)
    iso = 0.5
    reference = cmc33.extract(samples, iso)  # index frame: vertex = continuous index from the first sample
    top = cmc33.mesh_topology(reference)
    cases = {
        "oblique": ((0.7, 1.1, 1.3), (3.0, -2.0, 5.0), rotation((1, 2, 3), 0.7), (2, -1, 4)),
        "mirrored": ((0.5, 0.9, 1.2), (-1.0, 4.0, 0.5), rotation((3, -1, 2), 1.1) @ np.diag([1, -1, 1]), (0, 0, 0)),
        "negative spacing": ((0.8, -1.0, 0.6), (0.0, 0.0, 0.0), rotation((0, 1, 1), 0.4), (-3, 5, 1)),
    }
    for case, (spacing, origin, direction, first) in cases.items():
        image = image_of(samples, spacing, origin, direction, first)
        f = ExtractFilter()
        f.SetInputData(image)
        f.SetIsovalue(iso)
        f.SetThreads(2)
        f.Update()
        poly = f.GetOutput()
        points, triangles = polydata_arrays(poly)
        expected = physical(image, reference.vertices, first)
        scale = np.abs(expected).max()
        error = np.abs(points - expected).max()
        ok &= check(f"{case}: {len(points)} points at index-to-physical of extract's vertices", points.shape ==
                    expected.shape and error <= 4 * np.finfo(np.float32).eps * scale, f"max error {error:.3g}")
        ok &= check(f"{case}: {len(triangles)} triangles", len(triangles) == reference.triangle_count)
        mirrored = np.linalg.det(np.asarray(direction) @ np.diag(spacing)) < 0
        ref = reference.triangles.astype(np.int64)
        ok &= check(f"{case}: the same triangles{', reversed' if mirrored else ''}",
                    np.array_equal(triangles, ref[:, [0, 2, 1]] if mirrored else ref))
        fd = poly.GetFieldData()
        euler = fd.GetArray("cmc33_euler").GetValue(0)
        betti = fd.GetArray("cmc33_betti").GetTuple3(0)
        embedded = fd.GetArray("cmc33_embedded").GetValue(0)
        ok &= check(f"{case}: field data euler {euler}, betti {betti}, embedded {embedded}",
                    euler == top.euler and betti == (top.components, top.b1, top.closed_components) and embedded == 1)
        ok &= check(f"{case}: point scalars named after the input, the isovalue",
                    poly.GetPointData().GetScalars().GetName() == "density"
                    and poly.GetPointData().GetScalars().GetRange() == (iso, iso))

    # the samples are read in place: a change in VTK's array shows in the view
    image = image_of(samples, (1, 1, 1), (0, 0, 0), np.eye(3), (0, 0, 0))
    view, frame = image_to_samples(image)
    image.GetPointData().GetScalars().SetValue(5, 42.0)
    ok &= check("image_to_samples is a view of VTK's memory", view.reshape(-1)[5] == 42.0 and view.shape == samples.shape)

    # a cmc33.Volume to vtkImageData and back: the same samples and frame, the same mesh
    volume = cmc33.Volume(samples, (0.6, 0.8, 1.4), (1.0, 2.0, -3.0), rotation((2, -1, 1), 0.9))
    back, frame = image_to_samples(samples_to_image(volume))
    ok &= check("Volume -> vtkImageData -> samples and frame", np.array_equal(back, samples)
                and np.allclose(frame["spacing"], volume.spacing) and np.allclose(frame["origin"], volume.origin)
                and np.allclose(frame["direction"], volume.direction))
    f = ExtractFilter()
    f.SetInputData(samples_to_image(volume))
    f.SetIsovalue(iso)
    f.Update()
    points, triangles = polydata_arrays(f.GetOutput())
    world = cmc33.extract(volume, iso)
    ok &= check("the filter on it: cmc33.extract(volume)'s vertices and triangles",
                np.allclose(points, world.vertices, atol=1e-5) and np.array_equal(triangles, world.triangles))

    # several isovalues, normals, a named input array
    f = ExtractFilter()
    f.SetInputData(image_of(samples, (1, 1, 1), (0, 0, 0), np.eye(3), (0, 0, 0)))
    f.SetInputArrayToProcess(0, 0, 0, 0, "density")
    f.SetIsovalues([0.3, 0.6])
    f.SetComputeNormals(True)
    f.SetMethod("mc")
    f.Update()
    poly = f.GetOutput()
    counts = [cmc33.extract(samples, v, method="mc").triangle_count for v in (0.3, 0.6)]
    ok &= check(f"two isovalues: {poly.GetNumberOfCells()} triangles = {counts}", poly.GetNumberOfCells() == sum(counts))
    normals = poly.GetPointData().GetNormals()
    lengths = np.linalg.norm(numpy_support.vtk_to_numpy(normals), axis=1) if normals is not None else np.zeros(0)
    ok &= check("normals: unit, one per point", len(lengths) == poly.GetNumberOfPoints()
                and np.allclose(lengths, 1, atol=1e-5))
    ok &= check("field data: two tuples, method mc", poly.GetFieldData().GetArray("cmc33_euler").GetNumberOfTuples() == 2
                and poly.GetFieldData().GetAbstractArray("cmc33_method").GetValue(0) == "mc")

    # no isovalue (ParaView's Isosurfaces can be empty): an empty output, as vtkContourFilter's
    f.SetIsovalues([])
    f.Update()
    ok &= check("no isovalue: an empty output", f.GetOutput().GetNumberOfCells() == 0
                and f.GetOutput().GetFieldData().GetArray("cmc33_euler").GetNumberOfTuples() == 0)

    # bad input: a one-line error naming what is wrong
    vector = image_of(samples, (1, 1, 1), (0, 0, 0), np.eye(3), (0, 0, 0))
    try:
        three = numpy_support.numpy_to_vtk(np.zeros((samples.size, 3), dtype=np.float32), deep=1)
        three.SetName("velocity")
        vector.GetPointData().SetScalars(three)
        image_to_samples(vector)
        ok &= check("a 3-component array is refused", False)
    except ValueError as e:
        ok &= check("a 3-component array is refused", "3 components" in str(e), str(e))

    # an input error fails the request in one line, as VTK's filters do, and leaves no output
    nan = image_of(samples, (1, 1, 1), (0, 0, 0), np.eye(3), (0, 0, 0))
    nan.GetPointData().GetScalars().SetValue(7, float("nan"))
    f = ExtractFilter()
    f.SetInputData(nan)
    f.SetIsovalue(iso)
    f.Update()
    error = f.GetLastError() or ""
    ok &= check("NaN samples: an empty output and one line", f.GetOutput().GetNumberOfCells() == 0
                and "NaN" in error and "\n" not in error, error)
    f.SetInputData(image_of(samples, (1, 1, 1), (0, 0, 0), np.eye(3), (0, 0, 0)))
    f.Update()
    ok &= check("then a good input: the mesh, no error", f.GetOutput().GetNumberOfCells() == reference.triangle_count
                and f.GetLastError() is None)
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
