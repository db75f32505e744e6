#!/usr/bin/env bash
# Builds and tests the Python package (python/) the way a user installs it: a virtual environment
# that sees Debian's numpy and scikit-image (--system-site-packages), `pip install
# --no-build-isolation python/`, a wheel from `python3 -m build` installed into a second
# environment, then pytest against the installed package, with the command-line tool for the
# byte-for-byte tests. Nothing is downloaded. Work goes to build-python/ (and python/build/, the
# CMake tree pip and the wheel share). Usage: scripts/test-python.sh
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh --python --paraview
export CMAKE_BUILD_PARALLEL_LEVEL=${CMAKE_BUILD_PARALLEL_LEVEL:-2}
export CMC33_CMAKE_ARGS="-DCMC33_WERROR=ON ${CMC33_CMAKE_ARGS:-}"
work=build-python
rm -rf "$work"
mkdir -p "$work"

echo "== the command-line tool (the tests compare its files with the package's)"
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release -DCMC33_WERROR=ON >/dev/null
cmake --build build --target cmc33_cli

echo "== pip install --no-build-isolation python/"
/usr/bin/python3 -m venv --system-site-packages "$work/venv"
"$work/venv/bin/pip" install --quiet --no-build-isolation python/

echo "== wheel (python3 -m build --no-isolation --wheel), installed into a second environment"
(cd python && /usr/bin/python3 -m build --no-isolation --wheel --outdir "../$work/dist" >/dev/null)
/usr/bin/python3 -m venv --system-site-packages "$work/wheel-venv"
"$work/wheel-venv/bin/pip" install --quiet --no-index "$work"/dist/cmc33-*.whl
(cd "$work" && wheel-venv/bin/python -c '
import cmc33, numpy as np
verts, faces, normals, values = cmc33.marching_cubes(np.indices((9, 9, 9)).sum(axis=0), 12.5)
assert cmc33.mesh_topology((verts, faces)).nonmanifold_edges == 0 and len(faces) > 0
print("wheel:", cmc33.__file__)')

echo "== pytest"
CMC33_CLI="$PWD/build/cli/cmc33" "$work/venv/bin/python" -m pytest -q -p no:cacheprovider python/tests

echo "== cmc33.vtk and the ParaView plugin in pvbatch (tests/paraview; exit 77: skipped), on the wheel's package"
for test in test_vtk_filter.py "test_pvbatch.py --cmc33 build/cli/cmc33 --volume ../shared/data/volumes/aneurism_256x256x256_uint8.nrrd"; do
    # shellcheck disable=SC2086
    "$work/wheel-venv/bin/python" tests/paraview/$test || [[ $? -eq 77 ]]
done

echo "== cmc33.dask on a LocalCluster against the in-memory mesh (tests/dask; exit 77: skipped), with the wheel's module"
module=$("$work/wheel-venv/bin/python" -c 'import cmc33._cmc33 as m; print(m.__file__)')
/usr/bin/python3 tests/dask/test_dask.py --module "$module" --source . --shared ../shared || [[ $? -eq 77 ]]
