"""Builds the extension module cmc33._cmc33 with CMake, from the repository's own CMakeLists.txt
(-DCMC33_BUILD_PYTHON=ON), so the library's sources are compiled from the one place they live.
Everything else is in pyproject.toml.

Environment: CMAKE_BUILD_PARALLEL_LEVEL (jobs; default: every core), CMC33_CMAKE_ARGS (extra
configure arguments, split on spaces), CMAKE_GENERATOR (default Ninja when ninja is installed).
"""

import os
import re
import shlex
import shutil
import subprocess
import sys
from pathlib import Path

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent  # the repository: its CMakeLists.txt builds the library and the module


def project_version():
    text = (ROOT / "CMakeLists.txt").read_text(encoding="utf-8")
    match = re.search(r"project\(cmc33\s+VERSION\s+([0-9.]+)", text)
    if not match:
        sys.exit(f"setup.py: no 'project(cmc33 VERSION x.y.z' in {ROOT / 'CMakeLists.txt'}")
    return match.group(1)


class CMakeExtension(Extension):
    def __init__(self, name):
        super().__init__(name, sources=[])


class CMakeBuild(build_ext):
    """Configures (once) and builds the target cmc33_python in build_temp, then copies the module
    to where setuptools expects it. A second build (pip, then python -m build) reuses the tree."""

    def build_extension(self, ext):
        if shutil.which("cmake") is None:
            raise RuntimeError("cmake is not installed (Debian: apt-get install cmake ninja-build)")
        build = Path(self.build_temp).resolve() / "cmake"
        build.mkdir(parents=True, exist_ok=True)
        configure = ["cmake", "-S", str(ROOT), "-B", str(build), "-DCMAKE_BUILD_TYPE=Release",
                     "-DCMC33_BUILD_PYTHON=ON", "-DCMC33_BUILD_TESTS=OFF", "-DCMC33_BUILD_CLI=OFF",
                     f"-DPython3_EXECUTABLE={sys.executable}"]
        if not (build / "CMakeCache.txt").exists() and "CMAKE_GENERATOR" not in os.environ and shutil.which("ninja"):
            configure += ["-G", "Ninja"]
        configure += shlex.split(os.environ.get("CMC33_CMAKE_ARGS", ""))
        subprocess.run(configure, check=True)
        jobs = os.environ.get("CMAKE_BUILD_PARALLEL_LEVEL") or str(os.cpu_count() or 1)
        subprocess.run(["cmake", "--build", str(build), "--target", "cmc33_python", "-j", jobs], check=True)

        built = sorted((build / "python").glob("_cmc33*" + Path(self.get_ext_filename("x")).suffix))
        if len(built) != 1:
            raise RuntimeError(f"expected one _cmc33 module in {build / 'python'}, found {[p.name for p in built]}")
        target = Path(self.get_ext_fullpath(ext.name))
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(built[0], target)


setup(
    version=project_version(),
    package_dir={"": "src"},
    packages=["cmc33"],
    package_data={"cmc33": ["py.typed", "*.pyi"]},
    ext_modules=[CMakeExtension("cmc33._cmc33")],
    cmdclass={"build_ext": CMakeBuild},
)
