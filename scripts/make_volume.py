#!/usr/bin/env python3
"""Writes a large synthetic uint8 volume as an attached raw NRRD, one z plane at a time, so that
volumes larger than memory can be made (scripts/bench-slabs.sh: the out-of-core and MPI figures).

  make_volume.py OUT.nrrd NX NY NZ [--periods P]

f = sin(2 pi P x / NX + 0.3) + sin(2 pi P y / NY + 0.3) + sin(2 pi P z / NZ + 0.3), stored as
round(127.5 + 40 f) in 8..248: at iso 128 a smooth, connected surface of P periods along each
axis, with samples equal to the isovalue (ties). Needs numpy (scripts/install-deps.sh --bench).
"""

import argparse
import math
import os
import shutil
import sys

import numpy as np


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("out")
    p.add_argument("dims", type=int, nargs=3, metavar=("NX", "NY", "NZ"))
    p.add_argument("--periods", type=float, default=4.0)
    a = p.parse_args()
    nx, ny, nz = a.dims
    if min(nx, ny, nz) < 2:
        sys.exit("make_volume: every size must be at least 2")
    need = nx * ny * nz + 4096
    free = shutil.disk_usage(os.path.dirname(os.path.abspath(a.out))).free
    if need > free - (1 << 30):
        sys.exit("make_volume: %s needs %d bytes; only %d are free there (keeping 1 GiB)" % (a.out, need, free))
    w = 2 * math.pi * a.periods
    fx = np.sin(w * np.arange(nx) / nx + 0.3)
    fy = np.sin(w * np.arange(ny) / ny + 0.3)
    plane_xy = fy[:, None] + fx[None, :]
    tmp = a.out + ".part"
    with open(tmp, "wb") as f:
        f.write(("NRRD0004\ntype: uint8\ndimension: 3\nsizes: %d %d %d\nencoding: raw\n"
                 "# made by scripts/make_volume.py, %g periods per axis\n\n" % (nx, ny, nz, a.periods)).encode())
        for k in range(nz):
            plane = plane_xy + math.sin(w * k / nz + 0.3)
            f.write(np.rint(127.5 + 40.0 * plane).astype(np.uint8).tobytes())
    os.replace(tmp, a.out)


if __name__ == "__main__":
    main()
