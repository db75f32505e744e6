#!/usr/bin/python3
"""Times cmc33.marching_cubes against skimage.measure.marching_cubes from Python, and measures
that cmc33 reads the volume in place.

    bench/python_bench.py [--cases aneurism,bonsai,bonsai-fortran,CThead,sines512] [--repeat 3] [--volumes DIR]

Run it with the interpreter the package is installed for (a venv made by scripts/test-python.sh:
build-python/venv/bin/python bench/python_bench.py). For each case the volume is read (or, for
sines512, computed plane by plane: sin(a x + 0.3) + sin(a y + 0.3) + sin(a z + 0.3) on 512^3
float32, a = 2 pi 8 / 512, the field of bench/run_bench.sh; bonsai-fortran is bonsai copied to
Fortran order) outside the timing; then, on the same array, each tool is called REPEAT times
exactly as a user calls it and the median is reported:

  skimage           skimage.measure.marching_cubes(volume, level) (its own float32 conversion
                    included; always single-threaded)
  cmc33 mc, 1t      cmc33.marching_cubes(volume, level, threads=1)
  cmc33 mc, all     cmc33.marching_cubes(volume, level) (every core)
  cmc33 extract, 1t cmc33.extract(volume, level, threads=1, normals=True) (the native mesh)

Memory: for each case a fresh process reads the volume, resets its peak RSS (Linux
/proc/self/clear_refs), calls cmc33.marching_cubes once and prints how far the peak rose above
the RSS before the call, beside the size of the four arrays returned. A copy of the input would
add the input's size.

Prints a Markdown table and, with --json FILE, writes one JSON object per row. The machine is
named from /proc/cpuinfo and os.cpu_count(); timings on a busy machine are noise: check the load.
"""

import argparse
import json
import os
import platform
import statistics
import subprocess
import sys
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
CASES = {  # name: (file in the shared volumes or None for the computed field, isovalue)
    "aneurism": ("aneurism_256x256x256_uint8.nrrd", 80.0),
    "bonsai": ("bonsai_256x256x256_uint8.nrrd", 40.0),
    "bonsai-fortran": ("bonsai_256x256x256_uint8.nrrd", 40.0),  # the same samples in Fortran order
    "CThead": ("CThead_256x256x113_uint16.nrrd", 1500.0),
    "sines512": (None, 0.0),
}


def sines(n=512):
    import numpy as np
    a = 2 * np.pi * 8 / n
    s = np.sin(a * np.arange(n, dtype=np.float64) + 0.3)
    volume = np.empty((n, n, n), dtype=np.float32)
    plane = (s[:, None] + s[None, :]).astype(np.float64)
    for k in range(n):  # plane by plane: no volume-sized temporary
        volume[k] = plane + s[k]
    return volume


def load(case, volumes):
    import cmc33
    name, iso = CASES[case]
    if name is None:
        return sines(), iso
    samples = cmc33.read_volume(volumes / name).samples
    if case.endswith("-fortran"):
        import numpy as np
        samples = np.asfortranarray(samples)
    return samples, iso


def median_time(call, repeat):
    runs = []
    for _ in range(repeat):
        start = time.perf_counter()
        result = call()
        runs.append(time.perf_counter() - start)
        del result
    return statistics.median(runs), runs


def status_kib(key):
    for line in Path("/proc/self/status").read_text().splitlines():
        if line.startswith(key + ":"):
            return int(line.split()[1])
    raise KeyError(key)


def rss_probe(case, volumes):
    """In a fresh process: how far the resident set rises above its level before one
    cmc33.marching_cubes call (Linux: the peak is reset through /proc/self/clear_refs first, so
    that reading the file does not hide it)."""
    import cmc33
    volume, iso = load(case, volumes)
    Path("/proc/self/clear_refs").write_text("5")
    before = status_kib("VmRSS")
    arrays = cmc33.marching_cubes(volume, iso, threads=1)
    growth = (status_kib("VmHWM") - before) * 1024
    print(json.dumps({"growth": growth, "output": sum(a.nbytes for a in arrays), "input": volume.nbytes}))


def machine():
    model = "unknown CPU"
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                model = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    return f"{model}, {os.cpu_count()} logical CPUs, {platform.system()} {platform.release()}"


def main(argv):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--cases", default=",".join(CASES), help="comma-separated: " + ", ".join(CASES))
    parser.add_argument("--repeat", type=int, default=3, help="calls per tool and case (median; default 3)")
    parser.add_argument("--volumes", type=Path, default=REPO.parent / "shared" / "data" / "volumes")
    parser.add_argument("--json", type=Path, help="also write the rows as JSON lines here")
    parser.add_argument("--rss-probe", help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.rss_probe:
        rss_probe(args.rss_probe, args.volumes)
        return 0
    cases = [c for c in args.cases.split(",") if c]
    unknown = [c for c in cases if c not in CASES]
    if unknown or args.repeat < 1:
        parser.error(f"unknown cases {unknown}" if unknown else "--repeat must be at least 1")

    import numpy as np
    import cmc33
    from skimage import __version__ as skimage_version
    from skimage.measure import marching_cubes as skimage_mc

    print(f"machine: {machine()}; load average {os.getloadavg()[0]:.2f} at start")
    print(f"cmc33 {cmc33.__version__}, scikit-image {skimage_version}, numpy {np.__version__}, "
          f"Python {platform.python_version()}; median of {args.repeat}\n")
    print("| case | triangles (cmc33) | skimage s | cmc33 mc 1t s | × | cmc33 mc all s | × | "
          "cmc33 extract 1t s | peak RSS growth MiB | output MiB | input MiB |")
    print("|---|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|")
    rows = []
    for case in cases:
        volume, iso = load(case, args.volumes)
        sk, _ = median_time(lambda: skimage_mc(volume, iso), args.repeat)
        one, _ = median_time(lambda: cmc33.marching_cubes(volume, iso, threads=1), args.repeat)
        every, _ = median_time(lambda: cmc33.marching_cubes(volume, iso), args.repeat)
        native, _ = median_time(lambda: cmc33.extract(volume, iso, threads=1, normals=True), args.repeat)
        triangles = len(cmc33.marching_cubes(volume, iso)[1])
        input_bytes = volume.nbytes
        del volume
        probe = subprocess.run([sys.executable, __file__, "--rss-probe", case, "--volumes", str(args.volumes)],
                               check=True, capture_output=True, text=True)
        memory = json.loads(probe.stdout)
        row = {"case": case, "iso": iso, "triangles": triangles, "skimage_s": sk, "cmc33_mc_1t_s": one,
               "cmc33_mc_all_s": every, "cmc33_extract_1t_s": native, "speedup_1t": sk / one,
               "speedup_all": sk / every, "rss_growth": memory["growth"], "output_bytes": memory["output"],
               "input_bytes": input_bytes, "threads_all": os.cpu_count()}
        rows.append(row)
        mib = 2.0 ** 20
        print(f"| {case} iso {iso:g} | {triangles:,} | {sk:.4g} | {one:.4g} | {sk / one:.1f} | {every:.4g} | "
              f"{sk / every:.1f} | {native:.4g} | {memory['growth'] / mib:.1f} | {memory['output'] / mib:.1f} | "
              f"{input_bytes / mib:.1f} |", flush=True)
    print(f"\nload average {os.getloadavg()[0]:.2f} at the end")
    if args.json:
        with open(args.json, "w") as f:
            for row in rows:
                f.write(json.dumps(row) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
