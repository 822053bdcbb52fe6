// Linear systems from MatrixMarket files (written by a run's Output/Matrix Market steps, or by
// anyone): X.mtx, its right-hand side X_rhs.mtx (all ones if absent) and the node coordinates
// X_coordinates.mtx (one row of x, y, z per node, 3 dofs per node; written by viscompm), which
// multigrid preconditioners need. Read once, solved with any assembled solver configuration.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "viscompm/linalg/linear_solver.hpp"
#include "viscompm/parallel/communicator.hpp"

namespace viscompm::linalg {

struct MatrixMarketSolve {
  LinearSolveReport report;
  double apply_seconds = 0.0;                 ///< one application of A (mean of a few)
  double preconditioner_apply_seconds = 0.0;  ///< one application of the preconditioner (mean of a few)
};

/// The right-hand side and coordinate files that go with a matrix file: X.mtx → X_rhs.mtx,
/// X_coordinates.mtx.
std::string rhs_file_for(const std::string& matrix_file);
std::string coordinates_file_for(const std::string& matrix_file);

class MatrixMarketProblem {
 public:
  /// Reads the files (collective). With coordinates, the rows are distributed by node (all 3 dofs
  /// of a node on one rank), else evenly. InputError for unreadable or inconsistent files.
  MatrixMarketProblem(const std::string& matrix_file, const parallel::Communicator& comm);
  ~MatrixMarketProblem();
  MatrixMarketProblem(const MatrixMarketProblem&) = delete;
  MatrixMarketProblem& operator=(const MatrixMarketProblem&) = delete;

  std::int64_t rows() const;
  std::int64_t nonzeros() const;
  bool has_coordinates() const;
  /// Solves A x = b from x = 0 (collective). Throws InputError for matrix-free configurations
  /// (they need a scene); other failures of the preconditioner set-up propagate.
  MatrixMarketSolve solve(const SolverConfiguration& config) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace viscompm::linalg
