#include "viscompm/newton/newton_settings.hpp"

namespace viscompm::newton {

const ParameterTable<NewtonSettings>& NewtonSettings::table() {
  static const ParameterTable<NewtonSettings> t = [] {
    ParameterTable<NewtonSettings> table;
    using N = NewtonSettings;
    table.integer(&N::max_iterations, "Max iterations", 20, Range::at_least(1), "Newton iterations per step before Δt is halved")
        .real(&N::tolerance, "Tolerance", 1e-6, Range::positive(),
              "converged when the mass-weighted residual velocity is below Tolerance·Δx/Δt")
        .integer(&N::max_line_search_steps, "Max line search steps", 20, Range::at_least(1),
                 "halvings of the step before the line search gives up")
        .real(&N::armijo, "Armijo constant", 1e-4, Range::open_closed(0.0, 0.5),
              "sufficient decrease: E(v + α dv) ≤ E(v) + c α ∇E·dv + slack")
        .real(&N::energy_rounding, "Energy rounding", 1e-12, Range::closed(0.0, 1e-6),
              "the slack of the sufficient-decrease test, relative to Σ|terms of E|: E's terms cancel to "
              "rounding, so a converged step may not decrease E measurably")
        .choice(&N::hessian_projection, "Hessian projection", HessianProjection::adaptive,
                {{"always", HessianProjection::always}, {"adaptive", HessianProjection::adaptive},
                 {"never", HessianProjection::never}},
                "clamp each particle's ∂²Φ/∂A² to PSD so the matrix is SPD: always, or only when the exact "
                "Hessian fails (CG meets negative curvature, no descent, no decrease), or never")
        .choice(&N::hessian_update, "Hessian update", HessianUpdate::every_iteration,
                {{"every iteration", HessianUpdate::every_iteration}, {"every step", HessianUpdate::every_step},
                 {"lagged", HessianUpdate::lagged}},
                "assemble H at every Newton iteration (exact Newton), once per step, or keep it across steps while "
                "the graph and Δt are unchanged (lagged); a kept H is refreshed when the refresh rule fires")
        .choice(&N::preconditioner_update, "Preconditioner update", PreconditionerUpdate::every_assembly,
                {{"every assembly", PreconditionerUpdate::every_assembly},
                 {"every step", PreconditionerUpdate::every_step}, {"lagged", PreconditionerUpdate::lagged}},
                "set the preconditioner up after every assembly, after the first of each step, or keep it across "
                "steps while the graph is unchanged (refreshed when CG needs Refresh growth times its first count)")
        .real(&N::refresh_growth, "Refresh growth", 1.5, Range::at_least(1.0),
              "refresh rule: a kept H or preconditioner is rebuilt when a solve needs more than this times the CG "
              "iterations of the first solve after it was built")
        .real(&N::refresh_contraction, "Refresh contraction", 0.5, Range::open_closed(0.0, 1.0),
              "refresh rule: a kept H is rebuilt when the line search shortens the step or the residual shrinks by "
              "less than this factor in one iteration")
        .choice(&N::linear_tolerance, "Linear tolerance", LinearTolerance::fixed,
                {{"fixed", LinearTolerance::fixed}, {"eisenstat-walker", LinearTolerance::eisenstat_walker}},
                "CG's relative tolerance: the solver file's (fixed), or inexact Newton with Eisenstat-Walker forcing "
                "η_k = γ (r_k/r_{k-1})^α, safeguarded, between the solver file's tolerance and Forcing maximum")
        .real(&N::forcing_max, "Forcing maximum", 0.1, Range::open_closed(0.0, 0.9),
              "largest CG tolerance of inexact Newton (used at the first iteration)")
        .real(&N::forcing_gamma, "Forcing gamma", 0.9, Range::open_closed(0.0, 1.0), "γ of the Eisenstat-Walker forcing")
        .real(&N::forcing_exponent, "Forcing exponent", 2.0, Range::open_closed(1.0, 2.0),
              "α of the Eisenstat-Walker forcing");
    return table;
  }();
  return t;
}

}  // namespace viscompm::newton
