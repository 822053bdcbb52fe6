// The parameters of the minimisation of the incremental potential (the scene's `Newton` list):
// the method (Newton, or L-BFGS as in HOT), convergence, line search, when each particle Hessian
// is projected to PSD, and the strategy that decides how often the Hessian and its
// preconditioner are rebuilt and how exactly each linear system is solved. Declared once with
// defaults, ranges and doc strings; enums parsed once.
#pragma once

#include "viscompm/core/parameters.hpp"

namespace viscompm::newton {

/// How each iteration's direction is found.
enum class Method {
  newton,  ///< solve H dv = −∇E with the configured Krylov solver and preconditioner
  lbfgs    ///< L-BFGS whose initial inverse Hessian is one preconditioner application on the
           ///< SPD-projected H (Wang et al. 2020, "HOT"); no Krylov solve
};

/// When each particle's ∂²Φ/∂A² is clamped to PSD so that H is SPD: always; only when the exact
/// Hessian fails (CG meets negative curvature, no descent, no decrease); never.
enum class HessianProjection { always, adaptive, never };

/// When H is assembled again. Between assemblies Newton keeps the last H (modified Newton); a
/// kept H is refreshed when the refresh rule fires (see NewtonSettings).
enum class HessianUpdate {
  every_iteration,  ///< exact Newton
  every_step,       ///< once per time step, refreshed by the rule
  lagged            ///< kept across steps while the graph and Δt are unchanged, refreshed by the rule
};

/// When the preconditioner is set up again for the current H.
enum class PreconditionerUpdate {
  every_assembly,  ///< after every assembly
  every_step,      ///< after the first assembly of each step
  lagged           ///< kept across steps while the graph is unchanged; refreshed when CG slows down
};

/// The relative residual each CG solve must reach.
enum class LinearTolerance {
  fixed,            ///< the solver file's tolerance (the paper)
  eisenstat_walker  ///< inexact Newton: tied to the Newton residual (Eisenstat–Walker choice 2)
};

struct NewtonSettings {
  Method method = Method::newton;
  int max_iterations = 20;
  double tolerance = 1e-6;
  int max_line_search_steps = 20;
  double armijo = 1e-4;
  double energy_rounding = 1e-12;
  double residual_fallback = 100.0;
  HessianProjection hessian_projection = HessianProjection::adaptive;
  HessianUpdate hessian_update = HessianUpdate::every_iteration;
  PreconditionerUpdate preconditioner_update = PreconditionerUpdate::every_assembly;
  double refresh_growth = 1.5;
  double refresh_contraction = 0.5;
  LinearTolerance linear_tolerance = LinearTolerance::fixed;
  double forcing_max = 0.1;
  double forcing_gamma = 0.9;
  double forcing_exponent = 2.0;
  int lbfgs_pairs = 8;
  int lbfgs_rebuild = 0;

  static const ParameterTable<NewtonSettings>& table();
};

}  // namespace viscompm::newton
