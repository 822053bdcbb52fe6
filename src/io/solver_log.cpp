#include "viscompm/io/solver_log.hpp"

#include <filesystem>
#include <iomanip>

#include "viscompm/core/error.hpp"

namespace viscompm::io {

SolverLog::SolverLog(const std::string& directory, bool is_root, int ranks, bool append)
    : is_root_(is_root), ranks_(ranks) {
  if (!is_root_) return;
  const auto path = std::filesystem::path(directory) / "solver.csv";
  const bool write_header = !append || !std::filesystem::exists(path);
  out_.open(path, append ? std::ios::app : std::ios::trunc);
  if (!out_) throw SimulationError("cannot write " + path.string());
  if (write_header) out_ << header << "\n";
}

void SolverLog::record(std::int64_t step, int newton_iteration, const linalg::LinearSolveReport& r) {
  if (!is_root_) return;
  out_ << step << ',' << newton_iteration << ',' << r.iterations << ',' << std::setprecision(6) << r.relative_residual
       << ',' << r.setup_seconds << ',' << r.solve_seconds << ",\"" << r.preconditioner << "\"," << ranks_ << ','
       << r.operator_seconds << ',' << r.tolerance << '\n';
  out_.flush();
}

}  // namespace viscompm::io
