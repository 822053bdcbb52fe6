// Newton's method on the incremental potential (§5.7, with the optimisation integrator of Gast
// et al. 2015): one bounded loop whose iterations have named steps —
//   residual → convergence test → direction (assemble, precondition, CG) → line search —
// and a strategy (NewtonSettings) that decides when H and its preconditioner are rebuilt, which
// may keep them across iterations and steps, and how exactly each linear system is solved.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "viscompm/implicit/incremental_potential.hpp"
#include "viscompm/linalg/linear_solver.hpp"
#include "viscompm/linalg/newton_system.hpp"
#include "viscompm/newton/newton_settings.hpp"

namespace viscompm::newton {

struct NewtonReport {
  bool converged = false;
  int iterations = 0;                          ///< Newton iterations (directions computed)
  double residual = 0.0;                       ///< final ‖g‖_{M⁻¹} / √(Σm) [velocity]
  double tolerance = 0.0;                      ///< the residual it had to reach
  std::vector<double> residual_history;        ///< residual before each iteration and at the end
  std::vector<linalg::LinearSolveReport> linear_solves;
  std::vector<double> step_lengths;            ///< accepted line-search step α per iteration
  int projected_solves = 0;                    ///< solves with the PSD-projected Hessian
  int backtracks = 0;                          ///< line-search halvings, all iterations
  int assemblies = 0;                          ///< H assembled (or its matrix-free pieces prepared)
  int preconditioner_setups = 0;
  double gradient_seconds = 0.0;               ///< ∇E evaluations
  double line_search_seconds = 0.0;
  std::string failure;                         ///< why it did not converge
  bool interrupted = false;                    ///< abandoned on a stop request (set_interrupt)

  /// One line: residuals and step lengths per iteration (for failure messages).
  std::string history() const;
};

/// The mass-weighted residual of a gradient: √(Σ_i |g_i|²/m_i / Σ_i m_i) over owned nodes (a
/// velocity: what Newton still has to correct, on average per unit mass).
double velocity_residual(const implicit::IncrementalPotential& potential, const NodeVectorField& g,
                         const parallel::Communicator& comm);

/// Called after each assembly with the Newton iteration (1-based) and the right-hand side −∇E.
using SystemObserver =
    std::function<void(int iteration, const linalg::NewtonSystem& system, const NodeVectorField& rhs)>;

class NewtonSolver {
 public:
  NewtonSolver(const NewtonSettings& settings, linalg::NewtonSystem& system, const parallel::Communicator& comm);

  /// Minimises E from the initial guess v (constraints already applied); v holds the result.
  /// Collective.
  NewtonReport solve(const implicit::IncrementalPotential& potential, NodeVectorField& v,
                     const SystemObserver& observer = {});
  /// Forgets the Hessian and preconditioner kept from earlier solves (after a failed step, at a
  /// checkpoint), so that the next solve starts as a fresh run would.
  void forget();
  /// A request to abandon the solve (e.g. a stop signal on this rank), asked before every
  /// iteration's direction; the ranks agree, so one rank's request ends every rank's solve.
  void set_interrupt(std::function<bool()> requested) { interrupt_ = std::move(requested); }
  const NewtonSettings& settings() const { return settings_; }

 private:
  struct Step;  // the state of one solve
  bool direction_and_line_search(Step& step, const NodeVectorField& g, NodeVectorField& dv);
  bool line_search(Step& step, const NodeVectorField& dv, double slope);
  double forcing(const Step& step) const;
  void assemble(Step& step, bool project);

  NewtonSettings settings_;
  linalg::NewtonSystem& system_;
  parallel::Communicator comm_;
  std::function<bool()> interrupt_;
  // What is kept from earlier iterations and solves.
  bool hessian_kept_ = false;           // the system holds an H assembled earlier
  bool kept_projected_ = false;
  double kept_dt_ = 0.0;
  std::uint64_t kept_pattern_ = 0;
  int hessian_baseline_cg_ = -1;        // CG iterations of the first solve after the last assembly
  int preconditioner_baseline_cg_ = -1; // ... after the last preconditioner set-up
  double preconditioner_dt_ = 0.0;      // the Δt of the H the preconditioner was set up for
  bool refresh_hessian_ = false;
  bool refresh_preconditioner_ = false;
};

}  // namespace viscompm::newton
