#!/usr/bin/env python3
"""cmc33-mpi against cmc33 extract: the same bytes and the same numbers for every rank count.

Usage: check_mpi.py --cmc33 EXE --cmc33-mpi EXE --mpirun MPIRUN --work DIR [--shared DIR] [--data DIR] CASE

Each CASE runs `cmc33 extract` once per volume and setting, then `mpirun -n P cmc33-mpi extract`
with the same arguments for P = 1, 2, 3, 4 (--oversubscribe on a small machine, and
--allow-run-as-root as root, for Open MPI), and requires the PLY files to be identical byte for
byte and the JSON reports to agree on vertices, triangles, subcases, topology (Euler
characteristic, Betti numbers, boundary loops, ...) and geometry.

Cases:
  real     the bundled Bucky volume and real volumes of ../shared/data/volumes (raw and gzip NRRD,
           8 and 16 bits, big-endian), every method on some, normals on some
  formats  generated noise as VTK binary, MetaImage with a data file, gzip NRRD, headerless raw
  seams    a volume whose rank boundaries (planes 3, 4, 6, 8, 9 of 13) are full of ambiguous faces
           and samples equal to the isovalue, at isovalues with and without ties
  limits   --memory-limit per rank: slabs within ranks, the same bytes
  errors   non-finite samples, a missing file, bad usage: rank 0's one line and exit code are
           cmc33's (message after the program name), and nothing is left in the output folder
Needs only the Python standard library.
"""

import argparse
import gzip
import json
import os
import random
import struct
import subprocess
import sys
import zlib

RANKS = (1, 2, 3, 4)


class Checker:
    def __init__(self, args):
        self.cmc33 = args.cmc33
        self.mpi = args.cmc33_mpi
        self.work = args.work
        self.shared = args.shared
        self.data = args.data
        os.makedirs(self.work, exist_ok=True)
        version = subprocess.run([args.mpirun, "--version"], capture_output=True, text=True).stdout
        self.mpirun = [args.mpirun]
        if "Open MPI" in version or "OpenRTE" in version:
            self.mpirun.append("--oversubscribe")
            if os.geteuid() == 0:
                self.mpirun.append("--allow-run-as-root")
        self.failures = []
        self.runs = 0

    def fail(self, what):
        print("FAIL: " + what, flush=True)
        self.failures.append(what)

    def run(self, command):
        self.runs += 1
        return subprocess.run(command, capture_output=True, text=True)

    def compare(self, volume, args, ranks=RANKS, mpi_args=()):
        """cmc33 extract VOLUME ARGS against cmc33-mpi extract for every rank count."""
        failures = len(self.failures)
        ref_ply = os.path.join(self.work, "ref.ply")
        ref = self.run([self.cmc33, "extract", volume, *args, "-o", ref_ply, "--json", "--quiet"])
        what = os.path.basename(volume) + " " + " ".join(args)
        if ref.returncode != 0:
            self.fail(what + ": cmc33 failed: " + ref.stderr)
            return
        expected = json.loads(ref.stdout)
        with open(ref_ply, "rb") as f:
            expected_bytes = f.read()
        for p in ranks:
            out_ply = os.path.join(self.work, "mpi.ply")
            got = self.run(self.mpirun + ["-n", str(p), self.mpi, "extract", volume, *args, *mpi_args, "-o", out_ply,
                                          "--json", "--quiet"])
            label = "%s %s, %d ranks" % (what, " ".join(mpi_args), p)
            if got.returncode != 0:
                self.fail(label + ": cmc33-mpi failed (%d): %s" % (got.returncode, got.stderr))
                continue
            with open(out_ply, "rb") as f:
                if f.read() != expected_bytes:
                    self.fail(label + ": the PLY differs from cmc33's")
            report = json.loads(got.stdout)
            for key in ("vertices", "triangles", "subcases", "topology", "input", "method", "normals"):
                if report[key] != expected[key]:
                    self.fail("%s: %s %s != %s" % (label, key, report[key], expected[key]))
            geometry, want = report["geometry"], expected["geometry"]
            if geometry is not None and geometry.get("welded") is None and want is not None:
                want = dict(want, welded=None)
            if geometry != want:
                self.fail("%s: geometry %s != %s" % (label, geometry, want))
            if report["ranks"] != p:
                self.fail("%s: ranks %s" % (label, report["ranks"]))
            os.remove(out_ply)
        if len(self.failures) == failures:
            print("ok: %s (ranks %s)" % (what + " " + " ".join(mpi_args), ",".join(map(str, ranks))), flush=True)


# ---- volumes written here (standard library only) --------------------------------------------

def nrrd(path, dims, type_name, fmt, values, encoding="raw", endian="little"):
    data = struct.pack(("<" if endian == "little" else ">") + fmt * len(values), *values)
    if encoding == "gzip":
        data = gzip.compress(data)
    header = "NRRD0004\ntype: %s\ndimension: 3\nsizes: %d %d %d\nendian: %s\nencoding: %s\nspacings: 0.5 1 2\n\n" % (
        type_name, dims[0], dims[1], dims[2], endian, encoding)
    with open(path, "wb") as f:
        f.write(header.encode() + data)


def vtk_binary(path, dims, values):
    header = ("# vtk DataFile Version 3.0\nnoise\nBINARY\nDATASET STRUCTURED_POINTS\nDIMENSIONS %d %d %d\n"
              "SPACING 1 1.5 0.75\nORIGIN -3 2 1\nPOINT_DATA %d\nSCALARS v float 1\nLOOKUP_TABLE default\n") % (
        dims[0], dims[1], dims[2], len(values))
    with open(path, "wb") as f:
        f.write(header.encode() + struct.pack(">" + "f" * len(values), *values))


def metaimage(path, dims, values):
    raw = os.path.splitext(path)[0] + ".data"
    with open(raw, "wb") as f:
        f.write(zlib.compress(struct.pack("<" + "h" * len(values), *values)))
    with open(path, "w") as f:
        f.write("ObjectType = Image\nNDims = 3\nDimSize = %d %d %d\nElementType = MET_SHORT\n"
                "ElementSpacing = 1 1 1\nCompressedData = True\nTransformMatrix = 0 1 0 -1 0 0 0 0 1\n"
                "ElementDataFile = %s\n" % (dims[0], dims[1], dims[2], os.path.basename(raw)))


def noise(n, seed, lo=-1.0, hi=1.0):
    rng = random.Random(seed)
    return [rng.uniform(lo, hi) for _ in range(n)]


def seam_volume(path):
    """13 planes: the boundaries of 2, 3 and 4 ranks (planes 3, 4, 6, 8, 9) are checkerboards
    (an ambiguous face in every cell face of the plane) with samples equal to 100; the planes
    between are random over 98, 100, 102 (ties and ambiguous cells everywhere)."""
    dims = (17, 15, 13)
    rng = random.Random(15)
    values = []
    for k in range(dims[2]):
        for j in range(dims[1]):
            for i in range(dims[0]):
                if k in (3, 4, 6, 8, 9):
                    v = 102 if (i + j) % 2 else 98
                    if (i * 7 + j * 3 + k) % 5 == 0:
                        v = 100
                else:
                    v = rng.choice((98, 100, 102))
                values.append(v)
    nrrd(path, dims, "uint8", "B", values)


# ---- cases ------------------------------------------------------------------------------------

def case_real(c):
    bucky = os.path.join(c.data, "Bucky_32x32x32_uint8.nrrd")
    for method in ("cmc33", "mc33-lewiner", "mc"):
        c.compare(bucky, ["-i", "100", "--method", method])
    c.compare(bucky, ["-i", "100.5", "--normals"])
    if not c.shared or not os.path.isdir(c.shared):
        print("note: no shared volumes folder; real volumes beyond Bucky skipped")
        return
    real = [("CThead_256x256x113_uint16.nrrd", ["-i", "650", "--normals"]),   # gzip, big-endian
            ("engine_256x256x128_uint8.nrrd", ["-i", "80"]),
            ("tooth_103x94x161_uint8.nrrd", ["-i", "120", "--method", "mc33-lewiner"]),
            ("Cranium_256x256x108_int16.nrrd", ["-i", "1000"]),              # gzip, signed
            ("headsq_quarter_64x64x93_uint16.nrrd", ["-i", "500", "--method", "mc"]),
            ("HeadMRVolume_48x62x42_uint8.nrrd", ["-i", "50", "--normals"])]
    for name, args in real:
        path = os.path.join(c.shared, name)
        if os.path.exists(path):
            c.compare(path, args)


def case_formats(c):
    dims = (41, 37, 29)
    n = dims[0] * dims[1] * dims[2]
    values = noise(n, 1)
    vtk = os.path.join(c.work, "noise.vtk")
    vtk_binary(vtk, dims, values)
    c.compare(vtk, ["-i", "0.1", "--normals"])
    raw = os.path.join(c.work, "noise.bin")
    with open(raw, "wb") as f:
        f.write(b"HEADER--" + struct.pack(">" + "f" * n, *values))
    c.compare(raw, ["-i", "-0.2", "--dims", "41", "37", "29", "--type", "float", "--endian", "big",
                    "--header-bytes", "8"], ranks=(1, 3, 4))
    shorts = [int(v * 1000) for v in noise(n, 2)]
    mhd = os.path.join(c.work, "noise.mhd")
    metaimage(mhd, dims, shorts)
    c.compare(mhd, ["-i", "0", "--method", "mc33-lewiner"], ranks=(2, 3))
    gz = os.path.join(c.work, "noise_gzip.nrrd")
    nrrd(gz, dims, "double", "d", noise(n, 3), encoding="gzip", endian="big")
    c.compare(gz, ["-i", "0.05", "--normals"], ranks=(1, 2, 4))


def case_seams(c):
    path = os.path.join(c.work, "seams.nrrd")
    seam_volume(path)
    for iso in ("100", "99.5", "100.5"):
        for method in ("cmc33", "mc33-lewiner", "mc"):
            c.compare(path, ["-i", iso, "--method", method], ranks=(2, 3, 4) if method != "cmc33" else RANKS)
    c.compare(path, ["-i", "100", "--normals"], ranks=(4,), mpi_args=("--threads", "2"))


def case_limits(c):
    bucky = os.path.join(c.data, "Bucky_32x32x32_uint8.nrrd")
    c.compare(bucky, ["-i", "100", "--normals"], ranks=(1, 2, 3), mpi_args=("--memory-limit", "1M"))
    path = os.path.join(c.work, "limits.nrrd")
    dims = (160, 150, 40)
    values = []
    for k in range(dims[2]):
        for j in range(dims[1]):
            for i in range(dims[0]):
                values.append(min(255, int(((i - 80) ** 2 + (j - 75) ** 2 + (3 * (k - 20)) ** 2) ** 0.5)))
    nrrd(path, dims, "uint8", "B", values, encoding="gzip")
    c.compare(path, ["-i", "60.5"], ranks=(1, 2, 4), mpi_args=("--memory-limit", "5M"))


def case_errors(c):
    out_dir = os.path.join(c.work, "errors")
    os.makedirs(out_dir, exist_ok=True)
    dims = (8, 7, 30)
    values = [float(i + j + k - 10) for k in range(dims[2]) for j in range(dims[1]) for i in range(dims[0])]
    # far from the surface (every other corner of their cells is above): cells of case 1
    values[3 + 8 * (2 + 7 * 14)] = float("nan")
    values[5 + 8 * (6 + 7 * 25)] = float("-inf")
    bad = os.path.join(c.work, "nonfinite.nrrd")
    nrrd(bad, dims, "double", "d", values)
    out = os.path.join(out_dir, "out.ply")
    cases = [([bad, "-i", "0.5", "-o", out], 1),
             ([os.path.join(c.work, "missing.nrrd"), "-i", "1", "-o", out], 1),
             ([bad, "-i", "0.5", "-o", os.path.join(out_dir, "out.obj")], 2),
             ([bad, "-i", "0.5", "--method", "nope"], 2)]
    for args, code in cases:
        ref = c.run([c.cmc33, "extract", *args])
        for p in (1, 3):
            got = c.run(c.mpirun + ["-n", str(p), c.mpi, "extract", *args])
            label = "%s, %d ranks" % (" ".join(args), p)
            if got.returncode != code:
                c.fail("%s: exit %d, expected %d (%s)" % (label, got.returncode, code, got.stderr))
            first = got.stderr.splitlines()[0] if got.stderr else ""
            want = ref.stderr.splitlines()[0] if ref.stderr else "?"
            # the same message after the program's name (cmc33-mpi adds its own for .obj)
            if code == 1 and first.split(": ", 1)[-1] != want.split(": ", 1)[-1]:
                c.fail("%s: message %r, cmc33 says %r" % (label, first, want))
            if not first.startswith("cmc33-mpi: "):
                c.fail("%s: stderr does not start with 'cmc33-mpi: ': %r" % (label, got.stderr))
            if os.listdir(out_dir):
                c.fail("%s: left %s" % (label, os.listdir(out_dir)))
    if not c.failures:
        print("ok: errors", flush=True)


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--cmc33", required=True)
    parser.add_argument("--cmc33-mpi", required=True)
    parser.add_argument("--mpirun", required=True)
    parser.add_argument("--work", required=True)
    parser.add_argument("--shared", default="")
    parser.add_argument("--data", required=True)
    parser.add_argument("case", choices=("real", "formats", "seams", "limits", "errors"))
    args = parser.parse_args()
    checker = Checker(args)
    {"real": case_real, "formats": case_formats, "seams": case_seams, "limits": case_limits,
     "errors": case_errors}[args.case](checker)
    print("%d runs, %d failures" % (checker.runs, len(checker.failures)))
    return 1 if checker.failures else 0


if __name__ == "__main__":
    sys.exit(main())
