// Minimisation of the incremental potential (§5.7, with the optimisation integrator of Gast et
// al. 2015): one loop, bounded by `Max iterations`, whose iterations have named steps —
//   residual → convergence test → stop request → direction → line search —
// where the direction is Newton's (assemble, precondition, Krylov solve; at most
// `direction_attempts` tries, each with fresher or projected matrices) or L-BFGS's (two-loop
// recursion on one preconditioner application of the projected H; HOT, Wang et al. 2020).
// ReuseRules decides when H and its preconditioner are rebuilt; LinearSystem is the seam to
// linalg/.
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "viscompm/implicit/incremental_potential.hpp"
#include "viscompm/linalg/linear_solver.hpp"
#include "viscompm/linalg/newton_system.hpp"
#include "viscompm/newton/lbfgs_memory.hpp"
#include "viscompm/newton/linear_system.hpp"
#include "viscompm/newton/newton_settings.hpp"
#include "viscompm/newton/reuse_rules.hpp"
#include "viscompm/newton/solver_choice.hpp"

namespace viscompm::newton {

struct NewtonReport {
  bool converged = false;
  int iterations = 0;                          ///< iterations (directions computed)
  double residual = 0.0;                       ///< final ‖g‖_{M⁻¹} / √(Σm) [velocity]
  double tolerance = 0.0;                      ///< the residual it had to reach
  std::vector<double> residual_history;        ///< residual before each iteration and at the end
  std::vector<linalg::LinearSolveReport> linear_solves;  ///< one per Krylov solve (L-BFGS: per direction)
  std::vector<double> step_lengths;            ///< accepted line-search step α per iteration
  int projected_solves = 0;                    ///< solves with the PSD-projected Hessian
  int backtracks = 0;                          ///< line-search halvings, all iterations
  int residual_fallbacks = 0;                  ///< steps accepted on the residual (Residual fallback)
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
  /// Tries per Newton direction: as the strategy says; with a fresh H and preconditioner if a kept
  /// one was used; with the PSD-projected H if the exact one failed (Hessian projection adaptive).
  static constexpr int direction_attempts = 3;

  /// On the simulation's system.
  NewtonSolver(const NewtonSettings& settings, linalg::NewtonSystem& system, const parallel::Communicator& comm);
  /// On a measured choice's candidates: each Newton direction is computed with the one
  /// SolverChoice names, timed for it.
  NewtonSolver(const NewtonSettings& settings, const std::vector<linalg::NewtonSystem*>& candidates,
               const linalg::SolverChoiceSettings& choice, const parallel::Communicator& comm);
  /// On any system (tests); `system` must outlive the solver.
  NewtonSolver(const NewtonSettings& settings, LinearSystem& system, const parallel::Communicator& comm);
  ~NewtonSolver();

  /// Minimises E from the initial guess v (constraints already applied); v holds the result.
  /// Collective.
  NewtonReport solve(const implicit::IncrementalPotential& potential, NodeVectorField& v,
                     const SystemObserver& observer = {});
  /// Forgets the Hessian and preconditioner kept from earlier solves (after a failed step, at a
  /// checkpoint), so that the next solve starts as a fresh run would.
  void forget();
  /// A request to abandon the solve (e.g. a stop signal on this rank), asked before every
  /// iteration's direction and before each further attempt at one; the ranks agree, so one rank's
  /// request ends every rank's solve.
  void set_interrupt(std::function<bool()> requested) { interrupt_ = std::move(requested); }
  const NewtonSettings& settings() const { return settings_; }
  /// The candidate the next direction is computed with (0 without a measured choice).
  int candidate() const { return current_; }
  /// A measured choice's state (null for one system).
  const SolverChoice* choice() const { return choice_ ? &*choice_ : nullptr; }

 private:
  struct Step;  // the state of one solve
  struct Attempt {
    bool fresh;    // assemble H now (else the kept one)
    bool project;  // the PSD-projected H
  };
  /// Evaluates the residual g = ∇E(v) and records it; true when the solve ends here (converged,
  /// or an infeasible or non-finite state: report.failure says which).
  bool residual_settles(Step& step, NodeVectorField& g);
  bool stop_requested(Step& step) const;
  bool newton_direction_and_line_search(Step& step, const NodeVectorField& g, NodeVectorField& dv);
  bool try_newton_direction(Step& step, const NodeVectorField& rhs, double tolerance, const Attempt& attempt,
                            NodeVectorField& dv, bool& used_kept);
  bool lbfgs_direction_and_line_search(Step& step, const NodeVectorField& g, NodeVectorField& dv);
  /// The iterations the solve may take within the measured choice's budget (0: no limit).
  int budget_iteration_cap() const;
  void rebuild_initial_inverse(Step& step);
  bool line_search(Step& step, const NodeVectorField& dv, double slope);
  void trial_point(Step& step, const NodeVectorField& dv, double alpha) const;
  bool residual_decrease(Step& step, const NodeVectorField& dv, double& alpha);
  double forcing(const Step& step) const;
  void assemble(Step& step, bool project);
  void precondition(Step& step);

  /// Makes the choice's next candidate current for the next direction (its pattern built, its
  /// rules begun for this step if they were not).
  void select_candidate(Step& step);
  LinearSystem& system() { return *systems_[current_]; }
  const LinearSystem& system() const { return *systems_[current_]; }
  ReuseRules& rules() { return rules_[current_]; }

  NewtonSettings settings_;
  std::vector<std::unique_ptr<LinearSystem>> owned_systems_;
  std::vector<LinearSystem*> systems_;  ///< one, or a measured choice's candidates
  parallel::Communicator comm_;
  std::function<bool()> interrupt_;
  std::vector<ReuseRules> rules_;       ///< per system: what it keeps
  std::vector<bool> begun_;             ///< per system: its rules began this step's solve
  std::vector<std::uint64_t> set_up_for_;  ///< per system: the pattern its last preconditioner was set up on
  double fresh_setup_seconds_ = 0.0;    ///< this direction's set-ups on a new pattern (for the choice)
  std::chrono::steady_clock::time_point direction_start_;  ///< when this direction began
  std::vector<double> seconds_per_iteration_;  ///< per system: its Krylov iterations' recent cost (< 0: none yet)
  bool abandoned_ = false;              ///< this direction's solve ran out of the choice's budget
  /// Adaptive projection: an exact H failed as the first direction of a step since the last
  /// forget(); later steps then start from the projected H.
  bool exact_failed_first_ = false;
  int current_ = 0;
  std::optional<SolverChoice> choice_;
  LbfgsMemory lbfgs_;
};

}  // namespace viscompm::newton
