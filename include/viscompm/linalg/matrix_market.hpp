// Linear systems from MatrixMarket files (written by a run's Output/Matrix Market steps, or by
// anyone): read, distribute, solve with a solver configuration.
#pragma once

#include <cstdint>
#include <string>

#include "viscompm/linalg/linear_solver.hpp"
#include "viscompm/parallel/communicator.hpp"

namespace viscompm::linalg {

struct MatrixMarketSolve {
  LinearSolveReport report;
  std::int64_t rows = 0;
  std::int64_t nonzeros = 0;
  double apply_seconds = 0.0;  ///< one application of A (mean of a few)
};

/// The right-hand side file that goes with a matrix file: X.mtx → X_rhs.mtx.
std::string rhs_file_for(const std::string& matrix_file);

/// Reads a matrix (rows distributed evenly over the ranks) and its right-hand side (X_rhs.mtx;
/// all ones if there is none) and solves A x = b from x = 0. Throws InputError for unreadable
/// files and for matrix-free configurations (they need a scene).
MatrixMarketSolve solve_matrix_market(const std::string& matrix_file, const SolverConfiguration& config,
                                      const parallel::Communicator& comm);

}  // namespace viscompm::linalg
