#include "viscompm/io/solver_log.hpp"

#include <filesystem>
#include <iomanip>

namespace viscompm::io {

SolverLog::SolverLog(const std::string& directory, bool is_root, int ranks, bool append)
    : is_root_(is_root), ranks_(ranks), path_((std::filesystem::path(directory) / "solver.csv").string()) {
  if (!is_root_) return;
  const bool write_header = !append || !std::filesystem::exists(path_);
  out_.open(path_, append ? std::ios::app : std::ios::trunc);
  if (out_ && write_header) out_ << header << "\n" << std::flush;
}

void SolverLog::record(std::int64_t step, int newton_iteration, const linalg::LinearSolveReport& r) {
  if (!is_root_) return;
  out_ << step << ',' << newton_iteration << ',' << r.iterations << ',' << std::setprecision(6) << r.relative_residual
       << ',' << r.setup_seconds << ',' << r.solve_seconds << ",\"" << r.preconditioner << "\"," << ranks_ << ','
       << r.operator_seconds << ',' << r.tolerance << '\n';
  out_.flush();
}

}  // namespace viscompm::io
