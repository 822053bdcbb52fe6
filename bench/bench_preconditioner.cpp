// The cost of a preconditioner on MatrixMarket systems (written by a run's Output/Matrix Market
// steps), in one run: set-up, CG iterations and time to the solver file's tolerance, one
// application of A (SpMV) and one application of the preconditioner, and their ratio (a
// multigrid V-cycle in SpMVs).
//
//   mpiexec -np N build/bin/bench_preconditioner SOLVER.xml... -- MATRIX.mtx...
//
// Times are the slowest rank's; the preconditioner application is the mean of five after the
// solve (so that first-use allocations are not counted twice).
#include <Teuchos_TimeMonitor.hpp>

#include <cstdio>
#include <string>
#include <vector>

#include "viscompm/core/error.hpp"
#include "viscompm/linalg/environment.hpp"
#include "viscompm/linalg/linear_solver.hpp"
#include "viscompm/linalg/matrix_market.hpp"

using namespace viscompm;

int main(int argc, char** argv) {
  linalg::Environment environment(&argc, &argv);
  const parallel::Communicator comm(MPI_COMM_WORLD);
  std::vector<std::string> solvers, matrices;
  bool after_separator = false;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--help") {
      if (comm.rank() == 0)
        std::printf("usage: bench_preconditioner SOLVER.xml... -- MATRIX.mtx...\n"
                    "  per solver file and MatrixMarket system: set-up, CG iterations and time, one SpMV, one\n"
                    "  preconditioner application and their ratio (CSV on standard output)\n");
      return 0;
    }
    if (arg == "--") after_separator = true;
    else (after_separator ? matrices : solvers).push_back(arg);
  }
  if (solvers.empty() || matrices.empty()) {
    if (comm.rank() == 0) std::fprintf(stderr, "usage: bench_preconditioner SOLVER.xml... -- MATRIX.mtx...\n");
    return 2;
  }
  if (comm.rank() == 0)
    std::printf("matrix,rows,nonzeros,ranks,solver,setup_s,iterations,relative_residual,solve_s,spmv_s,"
                "preconditioner_apply_s,apply_in_spmvs,seconds_per_iteration\n");
  for (const auto& matrix : matrices) {
    const linalg::MatrixMarketProblem problem(matrix, comm);
    for (const auto& file : solvers) {
      const auto config = linalg::SolverConfiguration::read(file);
      const auto r = problem.solve(config);
      const double spmv = comm.max(r.apply_seconds), apply = comm.max(r.preconditioner_apply_seconds);
      const double setup = comm.max(r.report.setup_seconds), solve = comm.max(r.report.solve_seconds);
      if (comm.rank() == 0)
        std::printf("%s,%lld,%lld,%d,%s,%.4g,%d,%.3g,%.4g,%.4g,%.4g,%.3g,%.4g\n", matrix.c_str(),
                    static_cast<long long>(problem.rows()), static_cast<long long>(problem.nonzeros()), comm.size(),
                    config.label().c_str(), setup, r.report.iterations, r.report.relative_residual, solve, spmv, apply,
                    apply / spmv, solve / std::max(1, r.report.iterations));
      std::fflush(stdout);
    }
  }
  Teuchos::TimeMonitor::summarize();
  return 0;
}
