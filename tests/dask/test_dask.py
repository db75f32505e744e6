#!/usr/bin/env python3
"""cmc33.dask against the in-memory extraction: zarr stores with uneven chunks, on a
dask.distributed LocalCluster of 2 workers (threads: processes=False, since worker processes take
seconds to start and import), and on Dask's threaded and synchronous schedulers. The merged mesh
must have the vertex set and triangle set of cmc33.extract of the whole array, bit for bit (the
normals too), and its topology.

Run by CTest with --module (the built extension module) and --source (the repository); the
package is assembled in a temporary folder from python/src/cmc33 and that module. Exit 77 when
Dask, distributed or zarr is missing (scripts/install-deps.sh --python installs them).
"""
import argparse
import os
import sys
import tempfile
from pathlib import Path


def assemble(source: Path, module: Path, where: Path) -> None:
    package = where / "cmc33"
    package.mkdir(parents=True)
    for f in (source / "python" / "src" / "cmc33").iterdir():
        if f.is_file():
            (package / f.name).symlink_to(f)
    (package / module.name).symlink_to(module)
    sys.path.insert(0, str(where))


def canonical(mesh, normals=False):
    """Vertex rows as bytes and triangles as position triples rotated to start at their smallest
    vertex (keeping the winding), both sorted: the sets, independent of order."""
    import numpy as np
    v = np.ascontiguousarray(mesh.vertices, dtype=np.float32)
    rows = v.view(np.dtype((np.void, 12))).reshape(-1)
    t = np.asarray(mesh.triangles, dtype=np.int64)
    order = np.argsort(rows, kind="stable")
    rank = np.empty(len(rows), np.int64)
    rank[order] = np.arange(len(rows))
    tr = rank[t]
    shift = np.argmin(tr, axis=1)
    idx = (shift[:, None] + np.arange(3)[None, :]) % 3
    tr = np.take_along_axis(tr, idx, axis=1)
    tr = tr[np.lexsort(tr.T[::-1])]
    sorted_rows = v[order]
    n = np.asarray(mesh.normals)[order] if normals else None
    return sorted_rows, tr, n


def check_equal(name, got, want, normals):
    import numpy as np
    import cmc33
    gv, gt, gn = canonical(got, normals)
    wv, wt, wn = canonical(want, normals)
    problems = []
    if len(np.unique(gv.view(np.dtype((np.void, 12))))) != len(gv):
        problems.append("duplicate vertices")
    if gv.shape != wv.shape or not np.array_equal(gv.view(np.uint32), wv.view(np.uint32)):
        problems.append(f"vertex sets differ ({len(gv)} vs {len(wv)} vertices)")
    elif gt.shape != wt.shape or not np.array_equal(gt, wt):
        problems.append(f"triangle sets differ ({len(gt)} vs {len(wt)} triangles)")
    elif normals and not np.array_equal(gn.view(np.uint32), wn.view(np.uint32)):
        problems.append("normals differ")
    gtop, wtop = cmc33.mesh_topology(got), cmc33.mesh_topology(want)
    for field in ("vertices", "edges", "faces", "euler", "components", "boundary_edges", "nonmanifold_edges"):
        if hasattr(wtop, field) and getattr(gtop, field) != getattr(wtop, field):
            problems.append(f"topology {field}: {getattr(gtop, field)} vs {getattr(wtop, field)}")
    status = "ok" if not problems else "FAILED: " + "; ".join(problems)
    print(f"{name}: {len(wv)} vertices, {len(wt)} triangles: {status}", flush=True)
    return not problems


def smooth_field(n=96, seed=7):
    """A random-ish smooth field: a sum of random Gaussian bumps, with many components, handles
    and ambiguous faces at its isovalue."""
    import numpy as np
    rng = np.random.default_rng(seed)
    z, y, x = np.meshgrid(*(np.linspace(0, 1, n, dtype=np.float64),) * 3, indexing="ij")
    f = np.zeros((n, n, n))
    for _ in range(40):
        c = rng.random(3)
        s = 0.03 + 0.08 * rng.random()
        f += rng.choice([-1, 1]) * np.exp(-((x - c[0]) ** 2 + (y - c[1]) ** 2 + (z - c[2]) ** 2) / (2 * s * s))
    f += 0.05 * np.sin(37 * x + 11 * y) * np.cos(23 * z)
    return f.astype(np.float32)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--module", required=True, type=Path)
    parser.add_argument("--source", required=True, type=Path)
    parser.add_argument("--shared", type=Path, default=None)
    args = parser.parse_args()
    try:
        import dask
        import dask.array as da
        import distributed
        import zarr
    except ImportError as e:
        print(f"skipped: {e.name} is not installed (scripts/install-deps.sh --python)")
        return 77
    import numpy as np

    ok = True
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        assemble(args.source.resolve(), args.module.resolve(), tmp / "pkg")
        import cmc33
        import cmc33.dask as cd

        volumes = []
        field = smooth_field()
        volumes.append(("smooth 96^3 float32", field, 0.1, (40, 33, 50), (0.5, 1.25, 2.0), (1.0, -3.0, 0.25)))
        # uniform noise: every ambiguous case, thousands of interior vertices (tunnels, fans)
        noise = np.random.default_rng(3).random((30, 37, 41)).astype(np.float32)
        volumes.append(("noise 41x37x30 float32", noise, 0.5, (7, 11, 13), (0.3, 1.7, 2.5), (-5.5, 12.0, 7.25)))
        shared = args.shared or (args.source.resolve().parent / "shared")
        aneurism = shared / "data" / "volumes" / "aneurism_256x256x256_uint8.nrrd"
        if aneurism.is_file():
            samples = np.ascontiguousarray(cmc33.read_volume(aneurism).samples[60:180, 70:170, 50:190])
            volumes.append(("aneurism crop 140x100x120 uint8", samples, 80.5, (40, 33, 50), (1, 1, 1), (0, 0, 0)))
        else:
            print(f"(no {aneurism}: the real volume is left out)")

        cluster = distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=False,
                                           dashboard_address=None)
        client = distributed.Client(cluster)
        try:
            for name, samples, iso, chunks, spacing, origin in volumes:
                store = str(tmp / (name.split()[0] + ".zarr"))
                zarr.save_array(store, samples, chunks=chunks)
                arr = da.from_zarr(store)
                for method, normals in (("cmc33", False), ("cmc33", True), ("mc33-lewiner", True)):
                    want = cmc33.extract(samples, iso, spacing=spacing, origin=origin, method=method,
                                         normals=normals)
                    got = cd.extract_dask(arr, iso, spacing=spacing, origin=origin, method=method,
                                          normals=normals)
                    ok &= check_equal(f"{name} {method} normals={normals} chunks {chunks} (distributed)",
                                      got, want, normals)
            # other chunkings and schedulers: tiny and lopsided chunks, a last chunk of one sample
            big, small = field[:50, :41, :37], noise[:12, :21, :17]
            for samples, iso, chunks, scheduler in ((big, 0.1, (7, 41, 5), "threads"),
                                                    (big, 0.1, (49, 1, 36), "synchronous"),
                                                    (big, 0.1, (50, 41, 37), "synchronous"),
                                                    (small, 0.5, (2, 3, 2), "threads")):
                want = cmc33.extract(samples, iso, normals=True)
                arr = da.from_array(samples, chunks=chunks)
                got = cd.extract_dask(arr, iso, normals=True, scheduler=scheduler)
                shape = "x".join(str(n) for n in samples.shape[::-1])
                ok &= check_equal(f"{shape} at {iso}, chunks {chunks} ({scheduler})", got, want, True)
            # far from the origin the extractor keeps crossings further from the samples (2^-9 of
            # an edge past 1024 world units, 1/16 at 3e4 with a half spacing): the whole array's
            # margin, in every block, interior vertices (tunnels, fans) included
            for origin, spacing in (((0, 1e3, 0), (1, 1, 1)), ((3e4, -2e4, 0), (1, 0.5, 2))):
                want = cmc33.extract(noise, 0.5, spacing=spacing, origin=origin, normals=True)
                got = cd.extract_dask(da.from_array(noise, chunks=(7, 16, 9)), 0.5, spacing=spacing, origin=origin,
                                      normals=True, scheduler="threads")
                ok &= check_equal(f"noise at origin {origin}, spacing {spacing}, chunks (7, 16, 9) (threads)",
                                  got, want, True)
        finally:
            client.close()
            cluster.close()
        # refusals: one line, a ValueError
        for bad, kw, expected in (((da.zeros((4, 4)), 0.5), {}, "dimensions"),
                                  ((da.zeros((1, 4, 4)), 0.5), {}, "at least 2")):
            try:
                cd.extract_dask(*bad, scheduler="synchronous", **kw)
                print(f"{expected}: not refused")
                ok = False
            except ValueError as e:
                print(f"refused: {e}")
                ok &= expected in str(e)
    print("all equal" if ok else "FAILED")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
