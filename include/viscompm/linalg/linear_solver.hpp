// Solver configurations come from XML files (inputs/solvers/*.xml), never from code: the Krylov
// method (Belos), its parameters, and the preconditioner (Ifpack2 or MueLu) with its own
// parameter list. Reading a file validates it; a bad file is bad input (exit code 2).
#pragma once

#include <memory>
#include <string>
#include <vector>

namespace viscompm::linalg {

/// What one linear solve did; one row of solver.csv.
struct LinearSolveReport {
  int iterations = 0;
  double relative_residual = 0.0;  ///< ‖b − A x‖ / ‖b‖, computed after the solve
  double operator_seconds = 0.0;   ///< preparing H for this solve: assembly or matrix-free set-up (0: reused)
  double setup_seconds = 0.0;      ///< preconditioner set-up (0: reused)
  double solve_seconds = 0.0;      ///< Krylov iterations
  double tolerance = 0.0;          ///< the relative residual CG had to reach
  bool converged = false;
  std::string preconditioner;      ///< the configuration's label
  std::string failure;             ///< why the Krylov solver stopped early (empty if it did not throw)
};

/// A measured choice between solver files (a solver file with `Choose between`): how its trials
/// are scheduled, counted in time steps (newton::SolverChoice; doc/solvers.md).
struct SolverChoiceSettings {
  int recheck_steps = 16;       ///< steps of the chosen one before the next trial (doubled when confirmed)
  int max_recheck_steps = 256;  ///< the longest interval between trials
  double regime_change = 2.0;   ///< a trial at once when the chosen one's cost per step moves by this factor
  int regime_steps = 4;         ///< steps after a trial before a regime change is looked for
  double trial_overhead = 0.05; ///< the losers' trials cost at most this share of the winner's steps
};

class SolverConfiguration {
 public:
  /// Reads and validates a solver XML file. Throws InputError naming the file and parameter.
  static SolverConfiguration read(const std::string& file);
  /// The same from XML text (tests); `origin` names it in messages.
  static SolverConfiguration from_xml(const std::string& xml, const std::string& origin);

  /// Name written to solver.csv (the file's "Label", else derived from the preconditioner).
  const std::string& label() const;
  /// Where the configuration came from.
  const std::string& origin() const;
  /// True for the matrix-free Hessian (Operator = matrix-free).
  bool matrix_free() const;
  /// Throws InputError (naming the file and 'Ranks') when a run on `ranks` ranks is more than the
  /// file supports (any candidate's, for a measured choice).
  void check_rank_count(int ranks) const;
  /// A measured choice: the configurations it picks from, in the file's order (empty: this is one
  /// configuration). Only time integration runs a choice; everything else takes one configuration.
  const std::vector<SolverConfiguration>& candidates() const;
  bool is_choice() const { return !candidates().empty(); }
  const SolverChoiceSettings& choice() const;

  struct Impl;
  const Impl& impl() const { return *impl_; }

 private:
  std::shared_ptr<const Impl> impl_;
};

}  // namespace viscompm::linalg
