#!/usr/bin/env bash
# Installs the Debian packages cmc33 needs to build and test, and nothing else.
# Idempotent and quiet when everything is present.
# Usage: scripts/install-deps.sh [--bench] [--fuzz] [--mpi] [--paper] [--paraview] [--python] [--web]
#   --bench   also the peers the benchmark compares against (VTK, scikit-image)
#   --fuzz    also clang and its libFuzzer/sanitizer runtimes (scripts/fuzz.sh)
#   --mpi     also Open MPI, for cmc33-mpi and its tests (scripts/test-mpi.sh)
#   --paper   also what scripts/paper/all.sh needs for the paper's figures (matplotlib, VTK, and
#             xvfb: Debian's VTK renders off screen only through an X server)
#   --paraview also ParaView with its Python (pvbatch), for the plugin's test (tests/paraview; about
#             600 MB installed, so only scripts/test-python.sh asks for it). python3-paraview ships
#             VTK's Python modules itself and conflicts with python3-vtk9, which it then stands for.
#   --python  also what the Python package needs to build, test and show its examples (python/,
#             scripts/test-python.sh): pybind11, numpy, setuptools, venv, build, pytest, and the
#             peers its tests and README use (scikit-image, meshio, VTK)
#   --web     also emscripten, node and npm, and chromium for the page's browser tests (web/)
set -euo pipefail

# libcgal-dev is test-only: tests/topology/test_geometry_cgal.cpp checks mesh_geometry() against
# CGAL's self-intersection test (without it that test reports itself skipped).
# libgdcm-dev and libtiff-dev are the DICOM and TIFF readers' libraries (without them the build
# configures and refuses those formats by name); python3-pydicom and python3-tifffile write the
# volumes the DICOM and TIFF tests read (tests/io/*.py), as independent writers; python3-nibabel
# and python3-vtk9 write the NIfTI and .vti files of tests/io/independent_writers.py; python3-meshio
# reads back the PLY face properties of tests/io/test_mesh_ply_faces.cpp (VTK's PLY reader drops them).
packages=(g++ cmake ninja-build pkg-config zlib1g-dev libdeflate-dev libgmp-dev libgtest-dev libgmock-dev
          libcli11-dev nlohmann-json3-dev libtbb-dev python3 libcgal-dev
          libgdcm-dev libtiff-dev python3-numpy python3-pydicom python3-tifffile python3-nibabel python3-vtk9
          python3-meshio)
# node and npm run the Khronos glTF validator of tests/io/mesh_writers.py (tests/io/gltf); a node
# from elsewhere, with its own npm, is kept.
command -v node >/dev/null || packages+=(nodejs)
command -v npm >/dev/null || packages+=(npm)
for flag in "$@"; do
    case "$flag" in
    --bench) packages+=(libbenchmark-dev python3-vtk9 python3-skimage python3-numpy time) ;;
    --fuzz) packages+=(clang libclang-rt-14-dev) ;;
    --mpi) packages+=(libopenmpi-dev openmpi-bin) ;;
    --paraview) packages+=(paraview python3-paraview) ;;
    --web)
        # node-acorn: emscripten's optimizer requires it. node and npm only where there are none
        # (a node from elsewhere, with its own npm, is kept).
        packages+=(emscripten node-acorn chromium)
        command -v node >/dev/null || packages+=(nodejs)
        command -v npm >/dev/null || packages+=(npm)
        ;;
    --python) packages+=(python3-dev pybind11-dev python3-pybind11 python3-numpy python3-setuptools python3-wheel
                         python3-venv python3-pip python3-build python3-pytest python3-skimage python3-meshio
                         python3-vtk9 python3-dask python3-distributed python3-zarr) ;;
    --paper) packages+=(python3-matplotlib python3-numpy python3-vtk9 xvfb xauth) ;;
    *) echo "install-deps: unknown option \"$flag\"; expected --bench, --fuzz, --mpi, --paper, --paraview, --python or --web" >&2; exit 2 ;;
    esac
done

missing=()
installed() { dpkg-query -W -f='${Status}' "$1" 2>/dev/null | grep -q "install ok installed"; }
for p in "${packages[@]}"; do
    # python3-paraview's vtkmodules stand for python3-vtk9's (installing both removes one)
    [[ $p == python3-vtk9 ]] && { [[ " ${packages[*]} " == *" python3-paraview "* ]] || installed python3-paraview; } && continue
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
[[ ${#missing[@]} -eq 0 ]] && exit 0

echo "install-deps: installing ${missing[*]}" >&2
sudo=""
[[ $(id -u) -ne 0 ]] && sudo="sudo"
export DEBIAN_FRONTEND=noninteractive
# Another apt or dpkg (unattended upgrades, a second install) may hold the locks: wait for it as
# apt itself can (DPkg::Lock::Timeout), up to 10 minutes, instead of failing at once.
lock_wait=(-o DPkg::Lock::Timeout=600)
for attempt in $(seq 1 60); do
    if $sudo apt-get "${lock_wait[@]}" update -qq 2>"${TMPDIR:-/tmp}/install-deps.$$"; then
        rm -f "${TMPDIR:-/tmp}/install-deps.$$"
        break
    fi
    # apt-get update takes the lists' lock without waiting: retry while another apt holds it
    if ! grep -qi "lock" "${TMPDIR:-/tmp}/install-deps.$$" || [[ $attempt -eq 60 ]]; then
        cat "${TMPDIR:-/tmp}/install-deps.$$" >&2
        rm -f "${TMPDIR:-/tmp}/install-deps.$$"
        exit 1
    fi
    echo "install-deps: waiting for another package manager to release its lock ($attempt)" >&2
    sleep 10
done
$sudo apt-get "${lock_wait[@]}" install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
