// Newton's method on the incremental potential (DESIGN.md §3, §5.7): assemble H, precondition,
// CG for the direction, backtracking line search on E that rejects infeasible states.
#pragma once

#include <functional>
#include <vector>

#include "viscompm/core/parameters.hpp"
#include "viscompm/implicit/incremental_potential.hpp"
#include "viscompm/linalg/linear_solver.hpp"
#include "viscompm/linalg/newton_system.hpp"
#include "viscompm/linalg/node_space.hpp"

namespace viscompm::implicit {

struct NewtonSettings {
  int max_iterations = 20;
  double tolerance = 1e-6;
  int max_line_search_steps = 20;
  double armijo = 1e-4;
  std::string hessian_projection = "adaptive";

  static const ParameterTable<NewtonSettings>& table();
};

struct NewtonReport {
  bool converged = false;
  int iterations = 0;                          ///< Newton iterations (linear solves)
  double residual = 0.0;                       ///< final ‖g‖_{M⁻¹} / √(Σm) [velocity]
  double tolerance = 0.0;                      ///< the residual it had to reach
  std::vector<double> residual_history;        ///< residual before each iteration and at the end
  std::vector<linalg::LinearSolveReport> linear_solves;
  std::vector<double> step_lengths;            ///< accepted line-search step α per iteration
  int projected_solves = 0;                    ///< iterations that used the PSD-projected Hessian
  int backtracks = 0;                          ///< line-search halvings, all iterations
  std::string failure;                         ///< why it did not converge

  /// One line: residuals and step lengths per iteration (for failure messages).
  std::string history() const;
};

/// The mass-weighted residual of a gradient: √(Σ_i |g_i|²/m_i / Σ_i m_i) over owned nodes (a
/// velocity: what Newton still has to correct, on average per unit mass).
double velocity_residual(const IncrementalPotential& potential, const NodeVectorField& g,
                         const parallel::Communicator& comm);

/// Called after each assembly with the Newton iteration (1-based) and the right-hand side −∇E.
using SystemObserver = std::function<void(int iteration, const linalg::NewtonSystem& system, const NodeVectorField& rhs)>;

/// Minimises E from the initial guess v (constraints already applied). v holds the result.
NewtonReport newton_solve(const IncrementalPotential& potential, const linalg::NodeSpace& space,
                          linalg::NewtonSystem& system, const NewtonSettings& settings, NodeVectorField& v,
                          const SystemObserver& observer = {});

}  // namespace viscompm::implicit
