#include "viscompm/newton/newton_settings.hpp"

namespace viscompm::newton {

const ParameterTable<NewtonSettings>& NewtonSettings::table() {
  static const ParameterTable<NewtonSettings> t = [] {
    ParameterTable<NewtonSettings> table;
    using N = NewtonSettings;
    table.choice(&N::method, "Method", Method::newton, {{"newton", Method::newton}, {"L-BFGS", Method::lbfgs}},
                 "newton: solve H dv = −∇E with the solver file's Krylov method; L-BFGS: quasi-Newton directions "
                 "whose initial inverse Hessian is one application of the solver file's preconditioner on the "
                 "SPD-projected H, built once per step (HOT); same line search and convergence test")
        .integer(&N::max_iterations, "Max iterations", 20, Range::at_least(1),
                 "iterations (directions) per step before Δt is halved")
        .real(&N::tolerance, "Tolerance", 1e-6, Range::positive(),
              "converged when the mass-weighted residual velocity is below Tolerance·Δx/Δt")
        .integer(&N::max_line_search_steps, "Max line search steps", 20, Range::at_least(1),
                 "halvings of the step before the line search gives up")
        .real(&N::armijo, "Armijo constant", 1e-4, Range::open_closed(0.0, 0.5),
              "sufficient decrease: E(v + α dv) ≤ E(v) + c α ∇E·dv + slack")
        .real(&N::energy_rounding, "Energy rounding", 1e-12, Range::closed(0.0, 1e-6),
              "the slack of the sufficient-decrease test, relative to Σ|terms of E|: E's terms cancel to "
              "rounding, so a converged step may not decrease E measurably")
        .real(&N::residual_fallback, "Residual fallback", 100.0, Range::closed(0.0, 1e12),
              "near convergence E's rounding can hide any decrease: when no step length passes the energy test "
              "and the residual is below this many times the tolerance, take the longest step (halving) that "
              "reduces the residual instead; 0: never")
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
              "α of the Eisenstat-Walker forcing")
        .integer(&N::lbfgs_pairs, "L-BFGS pairs", 8, Range::closed(1, 100),
                 "L-BFGS: the (step, gradient change) pairs kept")
        .integer(&N::lbfgs_rebuild, "L-BFGS rebuild", 0, Range::closed(0, 1000000),
                 "L-BFGS: assemble the projected H and set its preconditioner up again after this many iterations "
                 "(0: once per step); also when the line search fails with an older one");
    return table;
  }();
  return t;
}

}  // namespace viscompm::newton
