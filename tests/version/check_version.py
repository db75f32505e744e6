#!/usr/bin/python3
"""One version everywhere: the CMake project's VERSION (passed as --version) must be what
`cmc33 --version` prints, what the Python package's setup.py reads, what the page's package.json
says, and a heading of CHANGELOG.md. Run by CTest (test `version_agrees`, label fast).

    check_version.py --version X.Y.Z --source REPO [--cli PATH/TO/cmc33]

Exit status 0 when they agree, 1 naming each one that does not.
"""

import argparse
import ast
import json
import re
import subprocess
import sys
from pathlib import Path


def setup_py_version(source):
    """The version python/setup.py gives the package: its own project_version(), run as written."""
    path = source / "python" / "setup.py"
    tree = ast.parse(path.read_text(encoding="utf-8"), str(path))
    functions = [n for n in tree.body if isinstance(n, ast.FunctionDef) and n.name == "project_version"]
    if not functions:
        return None, f"{path}: no project_version(); the package's version must come from CMakeLists.txt"
    scope = {"re": re, "sys": sys, "ROOT": source, "HERE": source / "python"}
    exec(compile(ast.Module(body=functions, type_ignores=[]), str(path), "exec"), scope)
    return scope["project_version"](), None


def main(argv):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--version", required=True)
    p.add_argument("--source", required=True, type=Path)
    p.add_argument("--cli")
    args = p.parse_args(argv)
    want, source, problems = args.version, args.source, []

    if args.cli:
        out = subprocess.run([args.cli, "--version"], capture_output=True, text=True)
        if out.returncode != 0 or out.stdout.strip() != f"cmc33 {want}":
            problems.append(f"`cmc33 --version` printed {out.stdout.strip()!r} (exit {out.returncode}); "
                            f"expected 'cmc33 {want}'")

    got, why = setup_py_version(source)
    if why:
        problems.append(why)
    elif got != want:
        problems.append(f"python/setup.py gives the package version {got}; expected {want}")
    pyproject = (source / "python" / "pyproject.toml").read_text(encoding="utf-8")
    static = re.search(r'^version\s*=\s*"([^"]*)"', pyproject, flags=re.M)
    if static and static.group(1) != want:
        problems.append(f"python/pyproject.toml says version {static.group(1)}; expected {want} (or dynamic)")
    module = (source / "python" / "ext" / "module.cpp").read_text(encoding="utf-8")
    if 'm.attr("version") = std::string(CMC33_VERSION_STRING)' not in module:
        problems.append("python/ext/module.cpp: cmc33.__version__ no longer comes from CMC33_VERSION_STRING")

    package_json = source / "web" / "package.json"
    web = json.loads(package_json.read_text(encoding="utf-8")).get("version")
    if web != want:
        problems.append(f"{package_json} says version {web}; expected {want}")

    changelog = (source / "CHANGELOG.md").read_text(encoding="utf-8")
    if not re.search(rf"^## {re.escape(want)}\b", changelog, flags=re.M):
        problems.append(f"CHANGELOG.md has no heading '## {want}'")

    for problem in problems:
        print(f"check_version.py: {problem}", file=sys.stderr)
    if not problems:
        print(f"version {want}: CMake, cmc33 --version, the Python package, web/package.json and CHANGELOG.md agree")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
