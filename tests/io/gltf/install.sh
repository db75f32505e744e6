#!/usr/bin/env bash
# Installs the pinned Khronos glTF validator (package-lock.json) into tests/io/gltf/node_modules,
# for tests/io/mesh_writers.py. Needs node and npm (scripts/install-deps.sh installs them).
set -euo pipefail
cd "$(dirname "$0")"
npm ci --no-audit --no-fund
