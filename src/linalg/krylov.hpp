// Belos CG (or the Krylov method of a SolverConfiguration) on Tpetra objects.
#pragma once

#include <BelosLinearProblem.hpp>
#include <BelosSolverManager.hpp>
#include <BelosTpetraAdapter.hpp>
#include "solver_configuration_impl.hpp"
#include "linalg_types.hpp"

namespace viscompm::linalg {

class KrylovSolver {
 public:
  explicit KrylovSolver(const SolverConfiguration& config);
  /// Solves A x = b from x = 0 to the relative residual `tolerance` (≤ 0: the configuration's),
  /// in at most `max_iterations` iterations (≤ 0: the configuration's `Maximum Iterations`).
  /// Failures (breakdown, no convergence) are reported, not thrown.
  LinearSolveReport solve(const Teuchos::RCP<const operator_type>& A, const Teuchos::RCP<operator_type>& M,
                          multivector_type& x, const multivector_type& b, double tolerance = 0.0,
                          int max_iterations = 0);
  /// The configuration's relative tolerance.
  double default_tolerance() const { return default_tolerance_; }

 private:
  SolverConfiguration config_;
  Teuchos::RCP<Belos::SolverManager<scalar_type, multivector_type, operator_type>> solver_;
  double default_tolerance_ = 1e-8;
  double current_tolerance_ = 1e-8;
  int default_max_iterations_ = 0;
  int current_max_iterations_ = 0;
};

}  // namespace viscompm::linalg
