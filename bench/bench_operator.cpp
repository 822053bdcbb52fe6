// The Newton operator's costs on one system, in one run: building the graph (node partition,
// maps, Import, CrsMatrix from local arrays), assembling the values, the matrix-free set-up and
// Hessian-vector product of the paper's solver, and the assembled SpMV against a STREAM-style
// triad on the same machine and ranks.
//
//   mpiexec -np N build/bin/bench_operator SCENE.xml CELL_SIZE [DT_IN_CFL] [REPETITIONS]
//
// Bytes counted for y = A x (CSR, Tpetra's local kernel): values (8) and column indices (4) per
// entry, row offsets (8) per row, x read once and y written once (8 + 8 per row): the least
// traffic any SpMV must move. The triad a = b + s c moves 24 bytes per element (STREAM's count).
// Times are the best of REPETITIONS (default 3), the slowest rank's.
#include <mpi.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "viscompm/linalg/environment.hpp"
#include "viscompm/linalg/linear_solver.hpp"
#include "viscompm/linalg/newton_system.hpp"
#include "viscompm/scene/scene.hpp"
#include "viscompm/simulation/simulation.hpp"

using namespace viscompm;

namespace {
double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// Best-of-10 triad bandwidth of this rank, arrays of `n` doubles (far beyond the caches).
double triad_bandwidth(std::size_t n) {
  std::vector<double> a(n, 0.0), b(n, 1.0), c(n, 2.0);
  const double s = 3.0;
  double best = 1e300;
  for (int trial = 0; trial < 10; ++trial) {
    MPI_Barrier(MPI_COMM_WORLD);
    const auto start = std::chrono::steady_clock::now();
    for (std::size_t i = 0; i < n; ++i) a[i] = b[i] + s * c[i];
    MPI_Barrier(MPI_COMM_WORLD);
    best = std::min(best, seconds_since(start));
  }
  if (a[n / 2] != 7.0) std::abort();  // keep the loop
  return 24.0 * static_cast<double>(n) / best;
}

// The best of `repetitions` runs of f, the slowest rank's time.
template <class F>
double best_of(int repetitions, const parallel::Communicator& comm, F&& f) {
  double best = 1e300;
  for (int k = 0; k < repetitions; ++k) {
    comm.barrier();
    const auto start = std::chrono::steady_clock::now();
    f();
    best = std::min(best, comm.max(seconds_since(start)));
  }
  return best;
}

// What one run measures (the slowest rank's best of `repetitions`).
struct OperatorTimes {
  double layout_with_graph, layout_kept, hessians_exact, hessians_projected, assembly_exact, assembly, spmv;
  double rows, nonzeros, spmv_bytes, mf_setup, mf_apply, triad, block_spmv, block_convert;
  long long own, ghosts, nodes;
};

OperatorTimes measure(simulation::Simulation& sim, double dt, int repetitions, const parallel::Communicator& comm) {
  OperatorTimes t{};
  auto& integrator = sim.integrator();
  // The layout of a step with a new graph, and with the graph kept: their difference is the
  // graph build (partition, maps and Import, CrsMatrix from local arrays).
  auto& particles = sim.particles();
  t.layout_with_graph = best_of(repetitions, comm, [&] {
    integrator.reset_reuse();
    integrator.build_layout(particles, dt);
    integrator.drop_ghosts(particles);
  });
  t.layout_kept = best_of(repetitions, comm, [&] {
    integrator.build_layout(particles, dt);
    integrator.drop_ghosts(particles);
  });
  integrator.prepare(particles, dt);
  const auto objective = integrator.build_objective(particles, 0.0, dt);

  // Where the assembly goes: the particles' 9×9 Hessians (materials, with or without the PSD
  // projection), then the elements and their scatter into the rows.
  const auto& potential = *objective->potential;
  const auto& v0 = objective->initial_guess;
  t.hessians_exact = best_of(repetitions, comm, [&] { (void)potential.particle_hessians(v0, false); });
  t.hessians_projected = best_of(repetitions, comm, [&] { (void)potential.particle_hessians(v0, true); });
  auto& assembled = integrator.newton_system();
  t.assembly_exact = best_of(repetitions, comm, [&] { assembled.assemble(potential, v0, false); });
  t.assembly = best_of(repetitions, comm, [&] { assembled.assemble(potential, v0, true); });
  t.spmv = assembled.time_apply(20);
  t.block_spmv = assembled.time_block_apply(20, t.block_convert);
  t.rows = static_cast<double>(assembled.global_rows());
  t.nonzeros = static_cast<double>(assembled.global_nonzeros());
  t.spmv_bytes = t.nonzeros * (8.0 + 4.0) + t.rows * (8.0 + 8.0 + 8.0);

  // Matrix-free: the particle Hessians and the exact diagonal, one Hessian-vector product.
  const std::string mf_file = std::string(VISCOMPM_SOURCE_DIR) + "/inputs/solvers/matrix_free_jacobi_cg.xml";
  linalg::NewtonSystem matrix_free(integrator.node_space(), linalg::SolverConfiguration::read(mf_file));
  t.mf_setup = best_of(repetitions, comm, [&] { matrix_free.assemble(potential, v0, true); });
  t.mf_apply = matrix_free.time_apply(20);

  t.triad = comm.sum(triad_bandwidth(std::size_t(40) << 20));  // 3 × 320 MiB per rank
  t.own = comm.sum(static_cast<std::int64_t>(integrator.layout().own_particle_count()));
  t.ghosts = comm.sum(static_cast<std::int64_t>(particles.size() - integrator.layout().own_particle_count()));
  t.nodes = integrator.node_space().global_node_count();
  return t;
}

void print(const OperatorTimes& t, const char* scene_file, double dx, double dt_cfl, int ranks) {
  std::printf("scene %s, dx %g, dt %g x CFL, %d rank(s): %lld particles (+%lld ghosts), %lld nodes, %.0f unknowns, "
              "%.0f nonzeros\n",
              scene_file, dx, dt_cfl, ranks, t.own, t.ghosts, t.nodes, t.rows, t.nonzeros);
  std::printf("layout with a new graph        %10.4f s\n", t.layout_with_graph);
  std::printf("layout with the graph kept     %10.4f s\n", t.layout_kept);
  std::printf("graph build                    %10.4f s\n", t.layout_with_graph - t.layout_kept);
  std::printf("particle Hessians, exact       %10.4f s\n", t.hessians_exact);
  std::printf("particle Hessians, projected   %10.4f s\n", t.hessians_projected);
  std::printf("assembly (values), exact       %10.4f s   elements and scatter %.4f s\n", t.assembly_exact,
              t.assembly_exact - t.hessians_exact);
  std::printf("assembly (values), projected   %10.4f s   elements and scatter %.4f s\n", t.assembly,
              t.assembly - t.hessians_projected);
  std::printf("assembled SpMV                 %10.5f s   %.2f GB/s\n", t.spmv, t.spmv_bytes / t.spmv / 1e9);
  std::printf("block SpMV (3x3 BlockCrsMatrix) %10.5f s   conversion %.4f s; block / point SpMV %.2f\n", t.block_spmv,
              t.block_convert, t.block_spmv / t.spmv);
  std::printf("matrix-free set-up (H_p, diag) %10.4f s\n", t.mf_setup);
  std::printf("matrix-free H·v                %10.5f s\n", t.mf_apply);
  std::printf("triad                                        %.2f GB/s\n", t.triad / 1e9);
  std::printf("SpMV / triad bandwidth         %10.2f\n", t.spmv_bytes / t.spmv / t.triad);
  std::printf("assembly (values) / H·v        %10.1f   (exact Hessians %.1f; elements and scatter alone %.1f)\n",
              t.assembly / t.mf_apply, t.assembly_exact / t.mf_apply, (t.assembly - t.hessians_projected) / t.mf_apply);
  std::printf("graph build / assembly         %10.2f\n", (t.layout_with_graph - t.layout_kept) / t.assembly);
  std::printf("assembly / matrix-free set-up  %10.2f\n", t.assembly / t.mf_setup);
  std::printf("matrix-free H·v / SpMV         %10.2f\n", t.mf_apply / t.spmv);
}
}  // namespace

int main(int argc, char** argv) {
  linalg::Environment environment(&argc, &argv);
  const parallel::Communicator comm(MPI_COMM_WORLD);
  const bool help = argc > 1 && std::string(argv[1]) == "--help";
  if (argc < 3 || help) {
    if (comm.is_root())
      std::fprintf(help ? stdout : stderr,
                   "usage: bench_operator SCENE.xml CELL_SIZE [DT_IN_CFL] [REPETITIONS]\n"
                   "  times the graph build, the assembly of H, one SpMV and the matrix-free set-up and product\n");
    return help ? 0 : 2;
  }
  // The cell size as an override, so that what derives from it (mesh voxels, nozzles) follows.
  const auto scene = scene::read_scene(argv[1], {{"Grid/Cell size", argv[2]}});
  const double dt_cfl = argc > 3 ? std::atof(argv[3]) : 10.0;
  const int repetitions = argc > 4 ? std::atoi(argv[4]) : 3;
  simulation::Simulation sim(
      scene, linalg::SolverConfiguration::read(std::string(VISCOMPM_SOURCE_DIR) + "/inputs/solvers/jacobi_cg.xml"), comm);
  double wave_speed = 0.0;
  for (const auto& m : sim.materials()) wave_speed = std::max(wave_speed, m->wave_speed());
  const OperatorTimes times = measure(sim, dt_cfl * sim.grid().dx / wave_speed, repetitions, comm);
  if (comm.is_root()) print(times, argv[1], scene.grid.cell_size, dt_cfl, comm.size());
  return 0;
}
