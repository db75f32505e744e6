#!/usr/bin/python3
"""Times scikit-image's marching cubes (Lewiner) on a NRRD volume, for bench/run_bench.py.

    skimage_bench.py FILE ISO [--repeat 5]

Reads FILE (NRRD with the header attached; encodings raw and gzip; little or big endian; the types
int8, uint8, int16, uint16, int32, uint32, float, double) into a numpy array of shape (z, y, x) in
its own type, outside the timing. Then times skimage.measure.marching_cubes(volume, level=ISO,
method='lewiner') REPEAT times, exactly as a user calls it: the call includes skimage's own
conversion of the samples to float32 and the per-vertex normals it always computes. Prints one JSON
line: {"tool": "skimage-lewiner", "seconds": median, "runs_seconds": [...], "vertices": n,
"triangles": n, "threads": 1, "version": "0.19.3", ...}.

Exit codes: 0 measured, 1 the file could not be read or marching_cubes failed, 2 usage error.
"""

import argparse
import gzip
import json
import statistics
import sys
import time
import zlib

PROG = "skimage_bench.py"

# NRRD type names (and their spellings in the format specification) -> numpy kind and size.
NRRD_TYPES = {}
for _dtype, _names in {
    "i1": ("signed char", "int8", "int8_t"),
    "u1": ("uchar", "unsigned char", "uint8", "uint8_t"),
    "i2": ("short", "short int", "signed short", "signed short int", "int16", "int16_t"),
    "u2": ("ushort", "unsigned short", "unsigned short int", "uint16", "uint16_t"),
    "i4": ("int", "signed int", "int32", "int32_t"),
    "u4": ("uint", "unsigned int", "uint32", "uint32_t"),
    "f4": ("float",),
    "f8": ("double",),
}.items():
    for _name in _names:
        NRRD_TYPES[_name] = _dtype


class ReadError(Exception):
    """A volume file this reader cannot use; the message is one line."""


def read_nrrd(path):
    """Returns the samples of an attached-header NRRD file as a writable numpy array of shape
    (z, y, x), in the machine's byte order. The samples are read (or decompressed) straight into
    the array's buffer: the file is never held in memory besides it."""
    import numpy as np

    try:
        f = open(path, "rb")
    except OSError as e:
        raise ReadError(f"{path}: cannot open the file: {e.strerror}") from None
    with f:
        head = f.read(len(b"NRRD000"))
        if head != b"NRRD000":
            raise ReadError(f"{path}: not a NRRD file (no NRRD000N magic)")
        header = bytearray(head)
        while True:  # the header ends at the first empty line
            end = header.find(b"\n\n")
            if end >= 0:
                break
            more = f.read(4096)
            if not more:
                raise ReadError(f"{path}: the NRRD header has no end (an empty line)")
            header += more
        f.seek(end + 2)
        fields = {}
        for line in header[:end].decode("latin-1").split("\n")[1:]:
            if line.startswith("#") or not line.strip() or ":=" in line:  # comments, key/values
                continue
            key, sep, value = line.partition(":")
            if not sep:
                raise ReadError(f"{path}: NRRD header line {line!r} is not 'field: value'")
            fields[key.strip().lower()] = value.strip()

        def field(name):
            if name not in fields:
                raise ReadError(f"{path}: the NRRD header has no {name!r} field")
            return fields[name]

        for unsupported in ("data file", "datafile"):
            if unsupported in fields:
                raise ReadError(f"{path}: detached NRRD data ({unsupported!r}) is not supported; "
                                "use a file with the header attached")
        for skip in ("byte skip", "byteskip", "line skip", "lineskip"):
            if fields.get(skip, "0") != "0":
                raise ReadError(f"{path}: {skip!r} {fields[skip]} is not supported")
        type_name = " ".join(field("type").lower().split())
        if type_name not in NRRD_TYPES:
            raise ReadError(f"{path}: NRRD type {type_name!r} is not supported; expected int8, uint8, "
                            "int16, uint16, int32, uint32, float or double")
        dtype = NRRD_TYPES[type_name]
        if field("dimension") != "3":
            raise ReadError(f"{path}: dimension {fields['dimension']} is not 3")
        try:
            sizes = [int(s) for s in field("sizes").split()]
        except ValueError:
            raise ReadError(f"{path}: sizes {fields['sizes']!r} are not integers") from None
        if len(sizes) != 3 or min(sizes) < 1:
            raise ReadError(f"{path}: sizes {fields['sizes']!r} are not 3 positive integers")
        if dtype[1] != "1":
            endian = fields.get("endian", "").lower()
            if endian not in ("little", "big"):
                raise ReadError(f"{path}: endian {endian!r} is neither 'little' nor 'big' "
                                f"(required for {type_name} samples)")
            dtype = ("<" if endian == "little" else ">") + dtype
        encoding = field("encoding").lower()
        if encoding in ("gzip", "gz"):
            source = gzip.GzipFile(fileobj=f, mode="rb")  # also reads concatenated gzip members
        elif encoding == "raw":
            source = f
        else:
            raise ReadError(f"{path}: encoding {encoding!r} is not supported; expected raw or gzip")

        count = sizes[0] * sizes[1] * sizes[2]
        samples = np.empty(count, dtype=dtype)
        buffer = memoryview(samples).cast("B")
        filled = 0
        try:
            while filled < len(buffer):
                n = source.readinto(buffer[filled:])
                if not n:
                    break
                filled += n
        except (OSError, EOFError, zlib.error) as e:
            raise ReadError(f"{path}: the {encoding} data cannot be read: {e}") from None
        if filled < len(buffer):
            raise ReadError(f"{path}: {filled} bytes of samples, expected {len(buffer)} "
                            f"({sizes[0]}x{sizes[1]}x{sizes[2]} {type_name})")
    if not samples.dtype.isnative:  # swap in place, as every other tool of the benchmark does
        samples = samples.byteswap(inplace=True).view(samples.dtype.newbyteorder("="))
    return samples.reshape(sizes[2], sizes[1], sizes[0])


class ArgumentParser(argparse.ArgumentParser):
    """Usage errors in one line, exit status 2."""

    def error(self, message):
        print(f"{self.prog}: {message} (try --help)", file=sys.stderr)
        sys.exit(2)


def main(argv):
    parser = ArgumentParser(
        prog=PROG, description="Time skimage.measure.marching_cubes(method='lewiner') on a NRRD volume.")
    parser.add_argument("file", metavar="FILE", help="NRRD volume, header attached (raw or gzip)")
    parser.add_argument("iso", metavar="ISO", type=float, help="isovalue")
    parser.add_argument("--repeat", type=int, default=5, metavar="N",
                        help="runs; the median is reported (default 5)")
    args = parser.parse_args(argv)  # exits with status 2 on a usage error
    if args.repeat < 1:
        parser.error(f"--repeat {args.repeat} is not at least 1")

    try:
        import numpy as np
        import skimage
        from skimage.measure import marching_cubes
    except ImportError as e:
        print(f"{PROG}: cannot import {e.name} (Debian: apt-get install python3-skimage python3-numpy)",
              file=sys.stderr)
        return 1

    try:
        volume = read_nrrd(args.file)
    except ReadError as e:
        print(f"{PROG}: {e}", file=sys.stderr)
        return 1
    # Slice by slice, so that the check does not add a volume-sized array to the peak memory.
    if volume.dtype.kind == "f" and not all(np.isfinite(plane).all() for plane in volume):
        print(f"{PROG}: {args.file}: the volume has NaN or infinite samples", file=sys.stderr)
        return 1

    runs = []
    vertices = triangles = 0
    for _ in range(args.repeat):
        try:
            start = time.perf_counter()
            verts, faces, _normals, _values = marching_cubes(volume, level=args.iso, method="lewiner")
            stop = time.perf_counter()
        except (ValueError, RuntimeError) as e:
            message = " ".join(str(e).split())
            print(f"{PROG}: {args.file}: marching_cubes at level {args.iso:g} failed: {message}",
                  file=sys.stderr)
            return 1
        runs.append(stop - start)
        vertices, triangles = len(verts), len(faces)
        del verts, faces, _normals, _values  # free the mesh before the next run allocates one

    z, y, x = volume.shape
    print(json.dumps({
        "tool": "skimage-lewiner",
        "file": args.file,
        "iso": args.iso,
        "dims": [x, y, z],
        "type": str(volume.dtype),
        "seconds": statistics.median(runs),
        "runs_seconds": runs,
        "vertices": vertices,
        "triangles": triangles,
        "threads": 1,
        "version": skimage.__version__,
        "numpy_version": np.__version__,
    }))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
