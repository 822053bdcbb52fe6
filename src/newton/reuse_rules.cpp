#include "viscompm/newton/reuse_rules.hpp"

#include <algorithm>
#include <cmath>

namespace viscompm::newton {

void ReuseRules::begin_solve(double dt, std::uint64_t pattern, bool matrix_free) {
  current_dt_ = dt;
  current_pattern_ = pattern;
  // Matrix-free pieces belong to their step's particles: never kept across steps.
  if (settings_.hessian_update != HessianUpdate::lagged || matrix_free || kept_pattern_ != pattern || kept_dt_ != dt)
    hessian_kept_ = false;
  // A preconditioner of another pattern or of another Δt's H is set up again.
  if (!preconditioner_set_up_ || preconditioner_pattern_ != pattern || preconditioner_dt_ != dt)
    refresh_preconditioner_ = true;
  if (!hessian_kept_) preconditioner_matches_hessian_ = false;
  assembled_this_step_ = false;
  preconditioned_this_step_ = false;
}

void ReuseRules::residual(double previous, double current) {
  if (current > settings_.refresh_contraction * previous) refresh_hessian_ = true;
}

bool ReuseRules::assemble_now() const {
  return settings_.hessian_update == HessianUpdate::every_iteration || !hessian_kept_ || refresh_hessian_ ||
         (settings_.hessian_update == HessianUpdate::every_step && !assembled_this_step_);
}

bool ReuseRules::setup_now() const {
  if (refresh_preconditioner_) return true;
  if (preconditioner_matches_hessian_) return false;  // nothing new to follow
  return settings_.preconditioner_update == PreconditionerUpdate::every_assembly ||
         (settings_.preconditioner_update == PreconditionerUpdate::every_step && !preconditioned_this_step_);
}

void ReuseRules::assembled(bool projected) {
  hessian_kept_ = true;
  kept_projected_ = projected;
  kept_dt_ = current_dt_;
  kept_pattern_ = current_pattern_;
  hessian_baseline_cg_ = -1;
  refresh_hessian_ = false;
  assembled_this_step_ = true;
  preconditioner_matches_hessian_ = false;
}

void ReuseRules::preconditioned() {
  preconditioner_set_up_ = true;
  preconditioner_matches_hessian_ = true;
  preconditioner_dt_ = current_dt_;
  preconditioner_pattern_ = current_pattern_;
  preconditioner_baseline_cg_ = -1;
  refresh_preconditioner_ = false;
  preconditioned_this_step_ = true;
}

void ReuseRules::solved(int iterations, double tolerance) {
  // The refresh rule: CG slowing down means the kept H or preconditioner has gone stale. Solves
  // to different tolerances (inexact Newton) are compared by iterations per decade of reduction.
  const double decades = std::max(1.0, -std::log10(std::max(tolerance, 1e-300)));
  const double rate = iterations / decades;
  if (hessian_baseline_cg_ < 0) hessian_baseline_cg_ = rate;
  else if (rate > settings_.refresh_growth * hessian_baseline_cg_) refresh_hessian_ = true;
  if (preconditioner_baseline_cg_ < 0) preconditioner_baseline_cg_ = rate;
  else if (settings_.preconditioner_update == PreconditionerUpdate::lagged &&
           rate > settings_.refresh_growth * preconditioner_baseline_cg_)
    refresh_preconditioner_ = true;
}

void ReuseRules::line_search_step(double alpha) {
  if (alpha < 1.0) refresh_hessian_ = true;  // the refresh rule: a shortened step
}

void ReuseRules::demand_fresh() {
  refresh_hessian_ = true;
  refresh_preconditioner_ = true;
}

void ReuseRules::forget() {
  hessian_kept_ = false;
  refresh_hessian_ = false;
  refresh_preconditioner_ = true;
  preconditioner_matches_hessian_ = false;
}

}  // namespace viscompm::newton
