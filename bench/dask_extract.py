#!/usr/bin/env python3
"""cmc33.dask on a zarr store against `cmc33 extract --memory-limit` on the same samples as raw
(issue #41's campaign): wall time, each Dask worker's peak memory, the CLI's peak memory, and
whether the two meshes are the same vertex and triangle sets.

The volume is a smooth uint8 field (a gyroid's level sets, plus a slow bump), N^3 samples made
slab by slab into both a zarr store (C x C x C chunks) and a raw file, never whole in memory.
Dask runs on a dask.distributed LocalCluster of worker processes (one thread each; the default,
--scheduler distributed) or on Dask's threaded scheduler in this process (--scheduler threads,
--workers threads). On the cluster each worker's peak is its process's peak resident size, read
after the extraction, with the size it had before any block ran (interpreter, Dask, numpy, cmc33)
beside it.

    PYTHONPATH=<folder with the cmc33 package> /usr/bin/python3 bench/dask_extract.py \\
        --cmc33 build/cli/cmc33 --size 1024 --chunk 128 --work /tmp/dask-bench

The cmc33 package must be importable (an installed one, or python/src/cmc33 with the built
_cmc33 module beside it). Numbers: docs/performance.md ("Dask").
"""
import argparse
import os
import resource
import shutil
import subprocess
import sys
import time
from pathlib import Path

import numpy as np


def slab(n: int, z0: int, z1: int) -> np.ndarray:
    """Planes z0 .. z1 - 1 of the N^3 field, uint8 (nz, ny, nx)."""
    period = 2 * np.pi / 48.0  # a gyroid cell every 48 samples: a large surface at any size
    z = np.arange(z0, z1, dtype=np.float32)[:, None, None] * period
    y = np.arange(n, dtype=np.float32)[None, :, None] * period
    x = np.arange(n, dtype=np.float32)[None, None, :] * period
    g = np.sin(x) * np.cos(y) + np.sin(y) * np.cos(z) + np.sin(z) * np.cos(x)
    return np.clip(128 + 80 * g, 0, 255).astype(np.uint8)


def make(n: int, chunk: int, work: Path):
    import zarr
    raw, store = work / f"field_{n}.raw", work / f"field_{n}_c{chunk}.zarr"
    if raw.is_file() and raw.stat().st_size == n ** 3 and (store / ".zarray").is_file():
        return raw, store
    shutil.rmtree(store, ignore_errors=True)
    z = zarr.open(str(store), mode="w", shape=(n, n, n), chunks=(chunk,) * 3, dtype=np.uint8)
    with open(raw, "wb") as f:
        for z0 in range(0, n, chunk):
            block = slab(n, z0, min(z0 + chunk, n))
            z[z0:z0 + len(block)] = block
            f.write(block.tobytes())
    return raw, store


def canonical(vertices, triangles):
    """Sorted vertex rows and sorted triangles of vertex ranks rotated to their smallest vertex."""
    v = np.ascontiguousarray(vertices, dtype=np.float32)
    rows = v.view(np.dtype((np.void, 12))).reshape(-1)
    order = np.argsort(rows, kind="stable")
    rank = np.empty(len(rows), np.int64)
    rank[order] = np.arange(len(rows))
    t = rank[np.asarray(triangles, dtype=np.int64)]
    idx = (np.argmin(t, axis=1)[:, None] + np.arange(3)[None, :]) % 3
    t = np.take_along_axis(t, idx, axis=1)
    return v[order], t[np.lexsort(t.T[::-1])]


def peak_rss_mib() -> float:
    """This process's peak resident size (VmHWM: per address space, so not the size of the
    process that started it, which getrusage's ru_maxrss keeps across exec)."""
    with open("/proc/self/status") as f:
        for line in f:
            if line.startswith("VmHWM:"):
                return int(line.split()[1]) / 1024.0
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--cmc33", required=True, help="the command-line tool")
    parser.add_argument("--size", type=int, default=1024)
    parser.add_argument("--chunk", type=int, default=128)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--scheduler", choices=("distributed", "threads"), default="distributed",
                        help="a LocalCluster of worker processes, or Dask's threaded scheduler")
    parser.add_argument("--iso", type=float, default=127.5)
    parser.add_argument("--memory-limit", default="256M", help="the CLI's --memory-limit")
    parser.add_argument("--work", type=Path, default=Path("/tmp/cmc33-dask-bench"))
    parser.add_argument("--keep", action="store_true", help="keep the volume files for the next run")
    args = parser.parse_args()

    import cmc33
    import cmc33.dask as cd
    import dask.array as da
    import distributed

    n, c = args.size, args.chunk
    args.work.mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()
    raw, store = make(n, c, args.work)
    print(f"volume {n}^3 uint8, zarr chunks {c}^3: made in {time.perf_counter() - t0:.1f} s", flush=True)

    # the CLI on the raw file, streaming within --memory-limit (its own process: its peak alone),
    # without its checks of the mesh's topology and embedding, which cmc33.dask does not make
    ply = args.work / "cli.ply"
    cmd = [args.cmc33, "extract", str(raw), "--dims", str(n), str(n), str(n), "--type", "uint8", "-i", str(args.iso),
           "--memory-limit", args.memory_limit, "--no-topology", "-o", str(ply)]
    # GNU time reports the CLI's own peak (%M, KiB)
    timed = ["/usr/bin/time", "-f", "%M", "-o", str(args.work / "cli.time")] if Path("/usr/bin/time").is_file() else []
    t0 = time.perf_counter()
    subprocess.run(timed + cmd, check=True, stdout=subprocess.DEVNULL)
    cli_time = time.perf_counter() - t0
    cli_peak = int((args.work / "cli.time").read_text().split()[-1]) / 1024.0 if timed else float("nan")
    print(f"cmc33 extract --memory-limit {args.memory_limit} --no-topology: {cli_time:.1f} s, peak {cli_peak:.0f} MiB", flush=True)

    chunk_mib = c ** 3 / 2 ** 20
    arr = da.from_zarr(str(store))
    if args.scheduler == "threads":
        import dask
        with dask.config.set(num_workers=args.workers):
            t0 = time.perf_counter()
            mesh = cd.extract_dask(arr, args.iso, scheduler="threads")
            dask_time = time.perf_counter() - t0
        print(f"cmc33.dask, threaded scheduler, {args.workers} threads: {dask_time:.1f} s "
              f"({dask_time / cli_time:.2f}x the CLI); chunk {chunk_mib:.1f} MiB", flush=True)
    else:
        cluster = distributed.LocalCluster(n_workers=args.workers, threads_per_worker=1, processes=True,
                                           dashboard_address=None, memory_limit=0)
        client = distributed.Client(cluster)
        try:
            # what every worker imports anyway, so that the growth is the blocks' own
            client.run(lambda: [__import__(m) for m in ("cmc33.dask", "dask.array", "zarr", "numcodecs")])
            base = client.run(peak_rss_mib)
            t0 = time.perf_counter()
            mesh = cd.extract_dask(arr, args.iso)
            dask_time = time.perf_counter() - t0
            peaks = client.run(peak_rss_mib)
        finally:
            client.close()
            cluster.close()
        print(f"cmc33.dask, {args.workers} workers: {dask_time:.1f} s ({dask_time / cli_time:.2f}x the CLI); "
              f"chunk {chunk_mib:.1f} MiB", flush=True)
        for w in sorted(peaks):
            print(f"  worker peak {peaks[w]:.0f} MiB (before the blocks: {base[w]:.0f} MiB; "
                  f"growth {peaks[w] - base[w]:.0f} MiB = {(peaks[w] - base[w]) / chunk_mib:.1f} chunks)")

    cli_mesh = cmc33.read_mesh(ply)
    gv, gt = canonical(mesh.vertices, mesh.triangles)
    wv, wt = canonical(cli_mesh.vertices, cli_mesh.triangles)
    same_v = gv.shape == wv.shape and np.array_equal(gv.view(np.uint32), wv.view(np.uint32))
    same_t = same_v and gt.shape == wt.shape and np.array_equal(gt, wt)
    top_d, top_c = cmc33.mesh_topology(mesh), cmc33.mesh_topology(cli_mesh)
    same_top = (top_d.euler, top_d.components, top_d.nonmanifold_edges) == (top_c.euler, top_c.components, top_c.nonmanifold_edges)
    print(f"mesh: {len(wv)} vertices, {len(wt)} triangles; vertex set equal: {same_v}, triangle set equal: {same_t}, "
          f"topology equal: {same_top} (euler {top_d.euler}, components {top_d.components})")
    print(f"driver peak {peak_rss_mib():.0f} MiB")
    if not args.keep:
        ply.unlink()
        raw.unlink()
        shutil.rmtree(store)
    return 0 if same_v and same_t and same_top else 1


if __name__ == "__main__":
    sys.exit(main())
