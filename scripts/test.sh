#!/usr/bin/env bash
# Builds viscompm (installing what is missing) and runs the whole test suite with ctest,
# the MPI tests at their registered rank counts included. Extra arguments go to ctest.
set -euo pipefail
source "$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)/setup.sh"

cd "$BUILD_DIR"
ctest --output-on-failure -j "$JOBS" "$@"
