#!/usr/bin/env bash
# Regenerates the figures and data of Custodio et al. 2013's experiments (docs/paper.md):
# docs/figures/fig8_shared_face.*, fig12_render.*, fig13_components.*, fig14_nonmanifold.*.
# Installs what is missing (scripts/install-deps.sh --paper), builds the cmc33 CLI (Release) and
# runs each script with Debian's Python; each prints what it measured. Needs the volumes of
# ../shared/data/volumes (or CMC33_VOLUMES). About 3 minutes on 2 cores once built.
# Usage: scripts/paper/all.sh        (CI does not run it: it runs the tests only)
set -euo pipefail
cd "$(dirname "$0")/../.."
scripts/install-deps.sh --paper
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build -j2 --target cmc33_cli >/dev/null
export CMC33="$PWD/build/cli/cmc33"
for script in fig8_shared_face fig12_render fig13_components fig14_nonmanifold; do
    echo "== scripts/paper/$script.py"
    /usr/bin/python3 "scripts/paper/$script.py"
done
