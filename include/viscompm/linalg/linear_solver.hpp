// Solver configurations come from XML files (inputs/solvers/*.xml), never from code: the Krylov
// method (Belos), its parameters, and the preconditioner (Ifpack2 or MueLu) with its own
// parameter list. Reading a file validates it; a bad file is bad input (exit code 2).
#pragma once

#include <memory>
#include <string>

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
  /// file supports.
  void check_rank_count(int ranks) const;

  struct Impl;
  const Impl& impl() const { return *impl_; }

 private:
  std::shared_ptr<const Impl> impl_;
};

}  // namespace viscompm::linalg
