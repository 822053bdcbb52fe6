// When Newton assembles H again and sets its preconditioner up again: the strategy of
// NewtonSettings (Hessian update, Preconditioner update, the refresh rule) applied to what was
// kept from earlier iterations and steps. Plain logic (no Trilinos), so that it can be tested on
// its own; NewtonSolver asks it before each direction and tells it what happened.
#pragma once

#include <cstdint>

#include "viscompm/newton/newton_settings.hpp"

namespace viscompm::newton {

class ReuseRules {
 public:
  explicit ReuseRules(const NewtonSettings& settings) : settings_(settings) {}

  /// A new solve (one time step) at Δt on the system's sparsity pattern `pattern`. A kept H is
  /// usable only when lagged, assembled, on the same pattern and Δt; a preconditioner only on the
  /// same pattern and Δt (H = M + Δt² K).
  void begin_solve(double dt, std::uint64_t pattern, bool matrix_free);
  /// The residual at the start of an iteration after `previous`: the contraction rule.
  void residual(double previous, double current);

  /// True if the next direction needs H assembled (else the kept H is used).
  bool assemble_now() const;
  /// True if the kept H is the PSD-projected one.
  bool kept_projected() const { return kept_projected_; }
  /// True if the preconditioner must be set up now: it is stale (another pattern or Δt, a refresh),
  /// or H was assembled since its set-up and the strategy follows new values.
  bool setup_now() const;
  /// True while the preconditioner was set up for the H the system holds now.
  bool preconditioner_matches_hessian() const { return preconditioner_matches_hessian_; }

  /// H was assembled (projected or not).
  void assembled(bool projected);
  /// The preconditioner was set up for the current H.
  void preconditioned();
  /// A linear solve to the relative residual `tolerance` took `iterations`: the growth rule, on
  /// iterations per decade of reduction (tolerance 0.1 or looser counts as one decade).
  void solved(int iterations, double tolerance);
  /// The line search accepted step length `alpha` (< 1: the refresh rule).
  void line_search_step(double alpha);
  /// The next direction needs a fresh H and a fresh preconditioner (a kept one failed).
  void demand_fresh();
  /// Forgets everything kept (after a failed solve, a checkpoint).
  void forget();

 private:
  NewtonSettings settings_;
  // What is kept from earlier iterations and steps.
  bool hessian_kept_ = false;        // the system holds an H assembled earlier
  bool kept_projected_ = false;
  double kept_dt_ = 0.0;
  std::uint64_t kept_pattern_ = 0;
  bool preconditioner_set_up_ = false;  // for kept_pattern_ and preconditioner_dt_
  bool preconditioner_matches_hessian_ = false;
  double preconditioner_dt_ = 0.0;
  std::uint64_t preconditioner_pattern_ = 0;
  double hessian_baseline_cg_ = -1;         // CG iterations per decade of the first solve after the last assembly
  double preconditioner_baseline_cg_ = -1;  // ... after the last preconditioner set-up
  bool refresh_hessian_ = false;
  bool refresh_preconditioner_ = false;
  // This solve.
  double current_dt_ = 0.0;
  std::uint64_t current_pattern_ = 0;
  bool assembled_this_step_ = false;
  bool preconditioned_this_step_ = false;
};

}  // namespace viscompm::newton
