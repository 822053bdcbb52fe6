// DIR/solver.csv: one row per linear solve (doc/contracts.md), written by rank 0.
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
  /// False on rank 0 once opening or writing the file failed (the caller agrees across ranks).
  bool good() const { return !is_root_ || static_cast<bool>(out_); }
  const std::string& path() const { return path_; }

 private:
  bool is_root_;
  int ranks_;
  std::string path_;
  std::ofstream out_;
};

}  // namespace viscompm::io
