#!/bin/sh
# The label-map checks (tests/labels/label_checks.cpp) on many random label fields: FIELDS of each
# of six kinds (2, 3, 4 labels; i.i.d. and smooth; 5^3 to 9^3), default 3334 (20,004 fields).
# With SIGMA > 0 the labels are smoothed first (--smooth SIGMA, docs/labels.md "Smooth labels").
# Prints one line of failure counts per kind; exit 1 when a guarantee failed (docs/labels.md).
# usage: scripts/labels-sweep.sh BUILD_DIR [FIELDS [FIRST_SEED [SIGMA]]]
set -eu
build=${1:?usage: scripts/labels-sweep.sh BUILD_DIR [FIELDS [FIRST_SEED [SIGMA]]]}
fields=${2:-3334}
first=${3:-0}
sigma=${4:-0}
program="$build/tests/labels/labels_sweep"
if [ ! -x "$program" ]; then
    echo "labels-sweep.sh: $program not found (build the target labels_sweep first)" >&2
    exit 2
fi
exec "$program" "$fields" "$first" "$sigma"
