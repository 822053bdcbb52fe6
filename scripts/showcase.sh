#!/usr/bin/env bash
# Runs showcase scenes (inputs/scenes/paper/showcase/NAME.xml) one after another on RANKS MPI ranks
# under `nice -n 10` and /usr/bin/time -v, then measures each (scripts/measure_scenes.py):
#   OUT/NAME/frame_*.h5, surface_*.obj, OUT/NAME.time (wall, CPU, peak memory per rank),
#   OUT/NAME.log (the run's output), OUT/NAME.json (the measurements).
# Extra arguments after -- go to every run (e.g. --frames 2 for a trial).
#
# Usage: scripts/showcase.sh [--ranks N] [--out DIR] NAME... [-- viscompm options]
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
root="$(cd "$here/.." && pwd)"
RANKS=2
OUT=output/showcase
names=()
extra=()
while [ $# -gt 0 ]; do
  case "$1" in
    --ranks) RANKS="$2"; shift 2 ;;
    --out) OUT="$2"; shift 2 ;;
    --) shift; extra=("$@"); break ;;
    -h|--help) sed -n '2,8p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) names+=("$1"); shift ;;
  esac
done
[ ${#names[@]} -gt 0 ] || { echo "showcase.sh: name at least one scene of inputs/scenes/paper/showcase/" >&2; exit 2; }
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_rmaps_base_oversubscribe=1
mkdir -p "$OUT"
for name in "${names[@]}"; do
  scene="$root/inputs/scenes/paper/showcase/$name.xml"
  [ -f "$scene" ] || { echo "showcase.sh: $scene: no such scene" >&2; exit 2; }
  rm -rf "${OUT:?}/$name"
  echo "showcase.sh: $name started $(date -Is), load $(cut -d' ' -f1-3 /proc/loadavg)"
  status=0
  nice -n 10 /usr/bin/time -v -o "$OUT/$name.time" mpiexec -np "$RANKS" "$root/build/bin/viscompm" "$scene" \
    --output "$OUT/$name" "${extra[@]}" > "$OUT/$name.log" 2>&1 || status=$?
  echo "showcase.sh: $name exit $status $(date -Is), load $(cut -d' ' -f1-3 /proc/loadavg)," \
       "$(grep -E 'Elapsed' "$OUT/$name.time" | sed 's/.*: //') wall," \
       "$(grep -E 'Maximum resident' "$OUT/$name.time" | sed 's/.*: //') kB peak (largest process)"
  /usr/bin/python3 "$here/measure_scenes.py" "$OUT/$name" --scene "$name" --scene-file "$scene" \
    --json "$OUT/$name.json" > /dev/null || echo "showcase.sh: $name: measuring failed"
done
