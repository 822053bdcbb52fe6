#!/usr/bin/env bash
# Builds viscompm (installing what is missing) and runs the default scene, a small shooting
# sponge (Figure 5.2), on all cores. Usage: scripts/demo.sh [extra viscompm options]
# VISCOMPM_RANKS (a positive whole number) is checked before anything is built, the options by
# viscompm (one line naming the option, exit 2).
set -euo pipefail
case "${1:-}" in -h|--help) sed -n '2,5p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;; esac
RANKS="${VISCOMPM_RANKS:-$(nproc)}"
[[ "$RANKS" =~ ^[1-9][0-9]{0,4}$ ]] || { echo "demo.sh: VISCOMPM_RANKS='$RANKS' is not a positive whole number" >&2; exit 2; }
source "$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)/setup.sh"

OUTPUT="${VISCOMPM_DEMO_OUTPUT:-$VISCOMPM_ROOT/output/shooting_sponge}"
mpiexec -np "$RANKS" "$BUILD_DIR/bin/viscompm" "$VISCOMPM_ROOT/inputs/scenes/shooting_sponge.xml" --output "$OUTPUT" "$@"
echo
echo "Output: $OUTPUT"
echo "  ParaView:  paraview $OUTPUT/particles.xdmf"
echo "  h5py:      python3 -c \"import h5py; f = h5py.File('$OUTPUT/frame_00001.h5'); print(list(f['particles']))\""
echo "  solver:    $OUTPUT/solver.csv"
