"""pvbatch loads the cmc33 ParaView plugin, reads a volume with ParaView's reader and extracts it
with "CMC33 Isosurface"; the triangle and vertex counts and the topology (Euler characteristic,
Betti numbers, embedded) equal what `cmc33 extract VOLUME --iso ISO --json` prints.
Exit 77 when pvbatch (Debian: python3-paraview) or the volume is missing."""

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import package_path


def main():
    parser = package_path.arguments(__doc__)
    parser.add_argument("--cmc33", required=True, help="the cmc33 command-line tool")
    parser.add_argument("--volume", required=True)
    parser.add_argument("--iso", type=float, default=80.5)
    parser.add_argument("--pvbatch", default=shutil.which("pvbatch"))
    args = parser.parse_args()
    site = package_path.setup(args)
    if not args.pvbatch or not Path(args.pvbatch).exists():
        package_path.skip("pvbatch is not installed (Debian: paraview python3-paraview; scripts/install-deps.sh --paraview)")
    if not Path(args.volume).exists():
        package_path.skip(f"{args.volume} is missing (the shared volumes)")

    cli = subprocess.run([args.cmc33, "extract", args.volume, "--iso", str(args.iso), "--json"],
                         check=True, capture_output=True, text=True)
    expected = json.loads(cli.stdout)

    env = dict(os.environ, PYTHONPATH=os.pathsep.join([site] + [p for p in [os.environ.get("PYTHONPATH")] if p]))
    script = Path(__file__).resolve().parent / "pvbatch_extract.py"
    run = subprocess.run([args.pvbatch, str(script), args.volume, str(args.iso)], capture_output=True, text=True,
                         env=env, timeout=300)
    lines = [line for line in run.stdout.splitlines() if line.startswith("{")]
    if run.returncode != 0 or not lines:
        print(run.stdout + run.stderr)
        print(f"FAIL pvbatch exited with {run.returncode}")
        return 1
    got = json.loads(lines[-1])

    ok = True
    top = expected["topology"]
    pairs = [("triangles", got["triangles"], expected["triangles"]),
             ("vertices", got["vertices"], expected["vertices"]),
             ("euler", got["euler"], top["euler"]),
             ("betti", got["betti"], top["betti"]),
             ("embedded", got["embedded"], expected["geometry"]["embedded"]),
             ("manifold", got["manifold"], top["nonmanifold_edges"] == 0 and top["nonmanifold_vertices"] == 0)]
    for name, a, b in pairs:
        print(f"{'ok  ' if a == b else 'FAIL'} {name}: pvbatch {a}, cmc33 extract {b}")
        ok &= a == b
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
