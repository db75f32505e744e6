"""Makes ``import cmc33`` find the package under test: the one already importable (a virtual
environment with cmc33 installed, scripts/test-python.sh), or, with --module and --package, a
build's extension module beside the package's sources (CTest, a build with
-DCMC33_BUILD_PYTHON=ON), assembled as symbolic links in --work."""

import argparse
import os
import sys
from pathlib import Path


def arguments(description: str) -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(description=description)
    parser.add_argument("--module", help="the built extension module _cmc33*.so")
    parser.add_argument("--package", help="the package's sources (python/src/cmc33)")
    parser.add_argument("--work", default=".", help="a folder for the assembled package and outputs")
    return parser


def setup(args: argparse.Namespace) -> str:
    """Puts the package on sys.path and returns the folder that holds it (for PYTHONPATH)."""
    if args.module or args.package:
        if not (args.module and args.package):
            sys.exit("give both --module and --package, or neither")
        site = Path(args.work).resolve() / "site"
        package = site / "cmc33"
        package.mkdir(parents=True, exist_ok=True)
        sources = [Path(args.module).resolve()] + sorted(Path(args.package).resolve().iterdir())
        for source in sources:
            if source.name == "__pycache__":
                continue
            link = package / source.name
            if link.is_symlink() or link.exists():
                link.unlink()
            link.symlink_to(source)
        sys.path.insert(0, str(site))
        return str(site)
    import cmc33
    return os.path.dirname(os.path.dirname(os.path.abspath(cmc33.__file__)))  # not resolved: a link farm stays


def skip(why: str) -> None:
    """Exit code 77: CTest's SKIP_RETURN_CODE, for a tool that is not installed."""
    print(f"skipped: {why}")
    sys.exit(77)

