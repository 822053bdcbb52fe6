// DIR/solver.csv: one row per linear solve (DESIGN.md §4), written by rank 0.
#pragma once

#include <cstdint>
#include <fstream>
#include <string>

#include "viscompm/linalg/linear_solver.hpp"

namespace viscompm::io {

class SolverLog {
 public:
  static constexpr const char* header =
      "step,newton_iteration,linear_iterations,relative_residual,setup_seconds,solve_seconds,preconditioner,ranks,"
      "operator_seconds,tolerance";

  /// Opens DIR/solver.csv on rank 0 (append keeps earlier rows, e.g. after a restart).
  SolverLog(const std::string& directory, bool is_root, int ranks, bool append = false);
  void record(std::int64_t step, int newton_iteration, const linalg::LinearSolveReport& report);

 private:
  bool is_root_;
  int ranks_;
  std::ofstream out_;
};

}  // namespace viscompm::io
