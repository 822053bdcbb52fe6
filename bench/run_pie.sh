#!/bin/bash
# The pie at Δx 0.01, 2 frames through its impact, 2 ranks, with a solver file and any --set
# overrides: the run doc/performance.md pairs against the paper's solver.
#   bench/run_pie.sh SOLVER_FILE OUTPUT_DIR [--set ...]
set -euo pipefail
usage="usage: bench/run_pie.sh SOLVER_FILE OUTPUT_DIR [--set 'Path=value' ...]"
if [[ ${1:-} == -h || ${1:-} == --help ]]; then
  printf '%s\n%s\n' "$usage" "The pie at cell 0.01, 2 frames, 2 ranks (mpiexec), the output written to OUTPUT_DIR."
  exit 0
fi
if [[ $# -lt 2 ]]; then
  echo "bench/run_pie.sh: SOLVER_FILE and OUTPUT_DIR required; $usage" >&2
  exit 2
fi
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_rmaps_base_oversubscribe=1
root=$(cd "$(dirname "$0")/.." && pwd)
solver=$1 out=$2
shift 2
exec mpiexec -np 2 "$root/build/bin/viscompm" "$root/inputs/scenes/paper/pie.xml" --output "$out" --frames 2 \
  --set "Grid/Cell size=0.01" --solver "$solver" "$@"
