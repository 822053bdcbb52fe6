#!/usr/bin/env bash
# The measurements of doc/performance.md, one after the other on an otherwise idle machine.
# Usage: bench/run_benchmarks.sh [OUTPUT_DIR]   (after scripts/demo.sh or scripts/test.sh built)
set -euo pipefail
if [[ ${1:-} == -h || ${1:-} == --help ]]; then
  echo "usage: bench/run_benchmarks.sh [OUTPUT_DIR]"
  echo "Builds the benchmark targets and runs doc/performance.md's measurements into OUTPUT_DIR (default output/bench)."
  exit 0
fi
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
OUT="${1:-$ROOT/output/bench}"
BIN="$ROOT/build/bin"
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_rmaps_base_oversubscribe=1
mkdir -p "$OUT"
cmake --build "$ROOT/build" --target bench_operator viscompm_app viscompm_study_app -j "$(nproc)" >/dev/null
lscpu > "$OUT/lscpu.txt"

# 1. The operator: graph build, values assembly (particle Hessians, elements), matrix-free set-up
#    and product, SpMV against a triad.
for n in 1 2; do
  mpiexec -np $n "$BIN/bench_operator" "$ROOT/inputs/scenes/shooting_sponge.xml" 0.01 100 | tee "$OUT/operator_np$n.txt"
done

# 2. Preconditioners at three resolutions and two time steps (the step's Newton system and a random load).
mpiexec -np 1 "$BIN/viscompm-study" "$ROOT/inputs/studies/sponge_preconditioners.xml" --output "$OUT/preconditioners" | tee "$OUT/preconditioners.txt"
mpiexec -np 1 "$BIN/viscompm-study" "$ROOT/inputs/studies/sponge_preconditioners.xml" --output "$OUT/preconditioners_random" \
  --set "Right-hand side=random" | tee "$OUT/preconditioners_random.txt"

# 3. §5.7's Jacobi factor during the impact.
mpiexec -np 2 "$BIN/viscompm-study" "$ROOT/inputs/studies/sponge_jacobi_factor.xml" --output "$OUT/jacobi_factor" | tee "$OUT/jacobi_factor.txt"

# 4. MueLu reuse across Newton iterations and steps, on 6 frames of the default scene: the shipped
#    solver file against a copy with `reuse: type = none`. Usage: reuse_pair FILE REUSE LABEL RANKS
reuse_pair() {
  local file="$ROOT/inputs/solvers/$1.xml" no_reuse="$OUT/$1_no_reuse.xml"
  sed "s|<Parameter name=\"reuse: type\" type=\"string\" value=\"$2\"/>|<Parameter name=\"reuse: type\" type=\"string\" value=\"none\"/>|; s|value=\"$3\"|value=\"$3-no-reuse\"|" \
    "$file" > "$no_reuse"
  for solver in "$file" "$no_reuse"; do
    name=$(basename "$solver" .xml)
    mpiexec -np "$4" "$BIN/viscompm" "$ROOT/inputs/scenes/shooting_sponge.xml" --frames 6 --solver "$solver" \
      --output "$OUT/reuse_$name" | tee "$OUT/reuse_$name.txt"
  done
}
reuse_pair muelu_cg tP muelu-sa 1

# 5. Strong scaling of the default scene (the demo) on 1 and 2 ranks.
for n in 1 2; do
  /usr/bin/time -v mpiexec -np $n "$BIN/viscompm" "$ROOT/inputs/scenes/shooting_sponge.xml" --output "$OUT/demo_np$n" \
    > "$OUT/demo_np$n.txt" 2> "$OUT/demo_np$n.time"
done
# 6. MueLu variants (aggregation, dropping, smoothers) against the shipped configuration, Δx = 0.02 and 0.01.
mpiexec -np 1 "$BIN/viscompm-study" "$ROOT/bench/muelu_variants/study.xml" --output "$OUT/muelu_variants" | tee "$OUT/muelu_variants.txt"

# 7. The largest resolution that fits here (Δx = 0.005, ~16 GB, ~30 minutes).
/usr/bin/time -v mpiexec -np 1 "$BIN/viscompm-study" "$ROOT/bench/muelu_variants/largest.xml" --output "$OUT/largest" \
  > "$OUT/largest.txt" 2>&1

# 8. Whole frames at Δx = 0.01 on 2 ranks: the paper's solver against the assembled ones and the
#    geometric multigrid, each with the Newton strategies (exact, inexact, Hessian once per step,
#    lagged), to the same Newton tolerance (~45 minutes).
mpiexec -np 2 "$BIN/viscompm-study" "$ROOT/inputs/studies/sponge_frames.xml" --output "$OUT/sponge_frames" \
  | tee "$OUT/sponge_frames.txt"

# 9. Multigrid per Newton system: Δx 0.02 and 0.01 at 100x and 1000x CFL (the shipped study adds
#    Δx = 0.005 and 10x CFL: hours on this machine).
mpiexec -np 1 "$BIN/viscompm-study" "$ROOT/inputs/studies/sponge_multigrid.xml" --output "$OUT/multigrid" \
  --set "Cell sizes={0.02, 0.01}" --set "Time steps={100, 1000}" | tee "$OUT/multigrid.txt"

# 10. The demo before and after the assembly and multigrid work: BASELINE_BIN names the bin/ of a
#     build of the commit before them (git worktree add ../baseline d9da441; build it there).
if [[ -n "${BASELINE_BIN:-}" ]]; then
  for n in 1 2; do
    for which in new baseline; do
      bin="$BIN"; [[ $which == baseline ]] && bin="$BASELINE_BIN"
      /usr/bin/time -v mpiexec -np $n "$bin/viscompm" "$ROOT/inputs/scenes/shooting_sponge.xml" \
        --output "$OUT/demo_${which}_np$n" > "$OUT/demo_${which}_np$n.txt" 2> "$OUT/demo_${which}_np$n.time"
    done
  done
fi

# 11. The geometric hierarchy's reuse inside MueLu (RAP against none), 6 frames of the demo.
reuse_pair gmg_cg RAP gmg-chebyshev 2

# 12. The demo's padding and Newton strategy: Padding lookahead 0 and 2 (8 is the default), and
#     inexact Newton.
for la in 0 2; do
  mpiexec -np 2 "$BIN/viscompm" "$ROOT/inputs/scenes/shooting_sponge.xml" --set "Grid/Padding lookahead=$la" \
    --output "$OUT/demo_la${la}_np2" > "$OUT/demo_la${la}_np2.txt"
done
mpiexec -np 2 "$BIN/viscompm" "$ROOT/inputs/scenes/shooting_sponge.xml" --set "Newton/Linear tolerance=eisenstat-walker" \
  --output "$OUT/demo_ew_np2" > "$OUT/demo_ew_np2.txt"
echo "benchmarks in $OUT"
