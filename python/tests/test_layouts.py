"""Every sample type and memory layout read in place; threads; the GIL; Ctrl-C; progress."""

import json
import os
import signal
import subprocess
import sys
import textwrap
import threading
import time

import numpy as np
import pytest

import cmc33
from cmc33._arrays import as_samples
from conftest import DTYPES, ellipsoid


def field(dtype):
    """The ellipsoid scaled into the type's range (negative samples for signed types)."""
    base = ellipsoid(shape=(17, 21, 26))  # 100 at the centre, down to about -230 in the corners
    info = np.iinfo(dtype) if np.dtype(dtype).kind in "iu" else None
    if info is not None:
        low = info.min if info.min < 0 else 0
        base = low + (base - base.min()) / (base.max() - base.min()) * min(info.max - low, 10000)
        base = np.round(base)
    return base.astype(dtype)


def layouts(volume):
    """(name, array with the same samples as `volume`, laid out differently, without a copy of
    the samples beyond the one that builds the layout)."""
    nz, ny, nx = volume.shape
    padded = np.zeros((nz + 1, 2 * ny, nx + 7), dtype=volume.dtype)
    padded[1:, ::2, 3:3 + nx] = volume
    reversed_ = np.ascontiguousarray(volume[::-1, :, ::-1])
    return [("C", np.ascontiguousarray(volume)),
            ("Fortran", np.asfortranarray(volume)),
            ("strided", padded[1:, ::2, 3:3 + nx]),
            ("negative", reversed_[::-1, :, ::-1]),
            ("transposed", np.ascontiguousarray(volume.transpose(2, 0, 1)).transpose(1, 2, 0))]


def mesh_bytes(mesh):
    return mesh.vertices.tobytes(), mesh.triangles.tobytes(), mesh.normals.tobytes()


@pytest.mark.parametrize("dtype", DTYPES)
def test_every_type_and_layout_read_in_place_gives_the_same_mesh(dtype):
    volume = field(dtype)
    iso = float(np.quantile(volume, 0.6)) + (0.5 if volume.dtype.kind in "iu" else 0.01)
    reference = cmc33.extract(volume, iso, normals=True)
    reference_mc = cmc33.marching_cubes(volume, iso)
    assert reference.triangle_count > 100
    for name, view in layouts(volume):
        assert np.array_equal(view, volume)
        samples = as_samples(view)
        assert samples is view, f"{dtype} {name}: the Python layer copied or re-viewed the samples"
        assert mesh_bytes(cmc33.extract(view, iso, normals=True)) == mesh_bytes(reference), f"{dtype} {name}"
        for a, b in zip(cmc33.marching_cubes(view, iso), reference_mc):
            assert np.array_equal(a, b), f"{dtype} {name}"


def test_a_read_only_memory_map_is_read_in_place(tmp_path):
    volume = field("int16")
    np.save(tmp_path / "volume.npy", volume)
    mapped = np.load(tmp_path / "volume.npy", mmap_mode="r")
    assert not mapped.flags.writeable
    assert np.shares_memory(as_samples(mapped), mapped)
    iso = float(np.quantile(volume, 0.6)) + 0.5
    mesh = cmc33.extract(mapped, iso, normals=True)
    assert mesh.triangle_count > 100
    assert mesh_bytes(mesh) == mesh_bytes(cmc33.extract(volume, iso, normals=True))


def test_bool_is_read_as_uint8_in_place():
    volume = ellipsoid() > 0
    assert np.shares_memory(as_samples(volume), volume)
    for a, b in zip(cmc33.marching_cubes(volume), cmc33.marching_cubes(volume.astype(np.uint8), 0.5)):
        assert np.array_equal(a, b)


@pytest.mark.parametrize("other,native", [("float16", "float32"), ("int64", "float64"), ("uint64", "float64"),
                                          (">u2", "uint16"), (">f8", "float64")])
def test_other_types_are_converted(other, native):
    volume = field("uint8").astype(native)  # integers to 255: exact in every type here
    converted = volume.astype(other)
    assert as_samples(converted).dtype == np.dtype(native)
    for a, b in zip(cmc33.marching_cubes(converted, 100.5), cmc33.marching_cubes(volume, 100.5)):
        assert np.array_equal(a, b)


def test_a_zero_stride_volume_of_a_billion_samples_is_read_in_place():
    # 1000 planes of 1000 x 1000 through a zero stride: 10^9 samples, one megabyte of memory
    plane = np.zeros((1000, 1000), dtype=np.uint8)
    plane[490:510, 480:520] = 200
    volume = np.broadcast_to(plane, (1000, 1000, 1000))
    assert volume.strides[0] == 0
    verts, faces, _, _ = cmc33.marching_cubes(volume, 100.5, threads=0)
    # a square tube along axis 0, open at both ends
    assert verts[:, 0].min() == 0 and verts[:, 0].max() == 999
    topology = cmc33.mesh_topology((verts, faces))
    assert topology.components == 1 and topology.boundary_loops == 2 and topology.euler == 0


RSS_SCRIPT = textwrap.dedent("""
    import json, resource, sys
    import numpy as np
    import cmc33
    dtype, layout, api = sys.argv[1:4]
    n = 256
    shape = {"F": (n, n, n), "strided": (n, 2 * n, n + 9), "negative": (n, n, n)}[layout]
    storage = np.empty(shape, dtype=dtype, order="F" if layout == "F" else "C")
    volume = {"F": storage, "strided": storage[:, ::2, 5:5 + n], "negative": storage[::-1, ::-1]}[layout]
    y, x = np.mgrid[0:n, 0:n].astype(np.float32) - n / 2
    for k in range(n):  # plane by plane: no volume-sized temporary
        volume[k] = np.clip(100 - 0.02 * (x * x + y * y + (k - n / 2) ** 2), 0, 100).astype(dtype)
    def status_kib(key):
        for line in open("/proc/self/status"):
            if line.startswith(key + ":"):
                return int(line.split()[1])
    try:  # Linux: reset the peak, so that building the volume cannot hide a rise
        open("/proc/self/clear_refs", "w").write("5")
        before, peak = status_kib("VmRSS") * 1024, lambda: status_kib("VmHWM") * 1024
    except OSError:
        before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024
        peak = lambda: resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024
    if api == "extract":
        mesh = cmc33.extract(volume, 50.5, normals=True, threads=1)
        output = mesh.vertices.nbytes + mesh.triangles.nbytes + mesh.normals.nbytes
    else:
        arrays = cmc33.marching_cubes(volume, 50.5, threads=1)
        output = sum(a.nbytes for a in arrays)
    after = peak()
    print(json.dumps({"growth": after - before, "output": output, "input": int(volume.nbytes)}))
""")


@pytest.mark.parametrize("dtype,layout,api", [("float64", "F", "marching_cubes"), ("float64", "F", "extract"),
                                              ("uint8", "strided", "marching_cubes"),
                                              ("int16", "negative", "extract")])
def test_peak_memory_grows_by_the_output_not_the_input(tmp_path, dtype, layout, api):
    # a fresh process, so that its peak RSS before the call is the volume and the interpreter
    result = subprocess.run([sys.executable, "-c", RSS_SCRIPT, dtype, layout, api], check=True,
                            capture_output=True, text=True, cwd=tmp_path)
    m = json.loads(result.stdout)
    assert m["growth"] < m["output"] + 16 * 2 ** 20, m
    assert m["growth"] < m["input"] / 2, m


def test_every_thread_count_gives_the_same_bytes():
    volume = field("float32")
    iso = float(np.quantile(volume, 0.4))
    reference = mesh_bytes(cmc33.extract(volume, iso, normals=True, threads=1))
    reference_mc = [a.tobytes() for a in cmc33.marching_cubes(volume, iso, threads=1)]
    for threads in (2, 3, 5, 0):
        assert mesh_bytes(cmc33.extract(volume, iso, normals=True, threads=threads)) == reference
        assert [a.tobytes() for a in cmc33.marching_cubes(volume, iso, threads=threads)] == reference_mc
    for bad in (-1, 1025, 1.5, "2"):
        with pytest.raises(ValueError, match="threads"):
            cmc33.extract(volume, iso, threads=bad)


def long_volume(planes=8000):
    """planes * 10^7 samples through a zero stride (10 MB of memory): with 8000 planes a second or
    two of work on one thread; a small mesh (a thin tube along axis 0)."""
    plane = np.zeros((100, 100000), dtype=np.uint8)
    plane[50:54, 50000:50004] = 200
    return np.broadcast_to(plane, (planes, 100, 100000))


def test_the_gil_is_released_during_extraction():
    volume = long_volume(3000)
    done = threading.Event()
    result = {}

    def work():
        start = time.perf_counter()
        result["mesh"] = cmc33.extract(volume, 100.5, threads=1)
        result["seconds"] = time.perf_counter() - start
        done.set()

    worker = threading.Thread(target=work)
    worker.start()
    largest_gap, last, ticks = 0.0, time.perf_counter(), 0
    while not done.is_set():
        now = time.perf_counter()
        largest_gap, last, ticks = max(largest_gap, now - last), now, ticks + 1
    worker.join()
    assert result["mesh"].triangle_count > 0
    assert result["seconds"] > 0.3, "the extraction was too short to tell"
    # with the GIL held this thread would have stood still for the whole extraction
    assert largest_gap < min(0.25, result["seconds"] / 2), (largest_gap, result["seconds"], ticks)


@pytest.mark.parametrize("api", ["extract", "marching_cubes"])
def test_ctrl_c_stops_a_long_extraction_promptly(api):
    volume = long_volume()
    sent = {}

    def interrupt():
        sent["at"] = time.perf_counter()
        os.kill(os.getpid(), signal.SIGINT)

    timer = threading.Timer(0.3, interrupt)
    result = None
    # Python's own Ctrl-C handler, whatever this process inherited: a shell starts a background
    # job (`pytest &`) with SIGINT ignored, and Python then installs no handler of its own
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    start = time.perf_counter()
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt):
            if api == "extract":
                result = cmc33.extract(volume, 100.5, threads=1)
            else:
                result = cmc33.marching_cubes(volume, 100.5, threads=1)
        stopped = time.perf_counter()
    finally:
        timer.cancel()
        signal.signal(signal.SIGINT, previous)
    assert result is None, "the extraction ended before the interrupt reached it"
    assert "at" in sent and sent["at"] - start >= 0.3
    assert stopped - sent["at"] < 0.5, f"KeyboardInterrupt {stopped - sent['at']:.3f} s after SIGINT"


def test_progress_is_called_on_this_thread_and_can_cancel():
    volume = field("float32")
    iso = float(np.quantile(volume, 0.5))
    fractions = []
    caller = threading.get_ident()

    def progress(fraction):
        assert threading.get_ident() == caller
        fractions.append(fraction)

    mesh = cmc33.extract(volume, iso, progress=progress)
    assert mesh.triangle_count > 0
    assert fractions[-1] == 1.0 and fractions == sorted(fractions)

    with pytest.raises(cmc33.CancelledError, match="progress"):
        cmc33.extract(long_volume(), 100.5, threads=1, progress=lambda fraction: False)

    class Stop(Exception):
        pass

    def fail(fraction):
        raise Stop()

    with pytest.raises(Stop):
        cmc33.extract(long_volume(), 100.5, threads=1, progress=fail)
    with pytest.raises(ValueError, match="callable"):
        cmc33.extract(volume, iso, progress=3)
