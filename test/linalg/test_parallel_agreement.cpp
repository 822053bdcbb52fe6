// One rank and N ranks agree: the same assembled Newton matrix (global ids, values to rounding)
// and the same particles after full steps (to solver tolerance). The reference runs on a
// communicator holding rank 0 alone, inside the same test.
#include <gtest/gtest.h>

#include <map>

#include "gather.hpp"
#include "scenes.hpp"
#include "viscompm/simulation/simulation.hpp"

using namespace viscompm;

namespace {
using Entries = std::vector<std::tuple<long long, long long, double>>;

Entries first_newton_matrix(const parallel::Communicator& comm, std::int64_t& particle_count) {
  simulation::Simulation sim(testkit::sponge_scene(), testkit::jacobi_cg(1e-12), comm);
  auto& integrator = sim.integrator();
  integrator.build_layout(sim.particles());
  integrator.particles_to_grid(sim.particles());
  const auto objective = integrator.build_objective(sim.particles(), 0.0, 4e-3);
  integrator.newton_system().assemble(*objective->potential, objective->initial_guess, true);
  particle_count = comm.sum(static_cast<std::int64_t>(sim.particles().size()));
  return integrator.newton_system().gather_entries();
}
}  // namespace

TEST(ParallelAgreement, AssembledMatrixIsTheSameOnOneRankAndOnAll) {
  const parallel::Communicator world(MPI_COMM_WORLD);
  std::int64_t n_world = 0, n_solo = 0;
  const Entries all = first_newton_matrix(world, n_world);
  Entries reference;
  if (MPI_Comm solo = testkit::solo_communicator(); solo != MPI_COMM_NULL) {
    reference = first_newton_matrix(parallel::Communicator(solo), n_solo);
    MPI_Comm_free(&solo);
  }
  if (!world.is_root()) return;
  EXPECT_EQ(n_world, n_solo);
  ASSERT_EQ(all.size(), reference.size());
  double scale = 0.0, worst = 0.0;
  for (std::size_t k = 0; k < all.size(); ++k) {
    ASSERT_EQ(std::get<0>(all[k]), std::get<0>(reference[k]));
    ASSERT_EQ(std::get<1>(all[k]), std::get<1>(reference[k]));
    scale = std::max(scale, std::abs(std::get<2>(reference[k])));
    worst = std::max(worst, std::abs(std::get<2>(all[k]) - std::get<2>(reference[k])));
  }
  EXPECT_LT(worst, 1e-13 * scale);
  EXPECT_GT(all.size(), 10000u);
}

TEST(ParallelAgreement, FullStepsAreTheSameOnOneRankAndOnAll) {
  const parallel::Communicator world(MPI_COMM_WORLD);
  const double t_end = 0.02;  // several steps: migration, graph rebuilds, bullet contact
  simulation::Simulation sim(testkit::sponge_scene(), testkit::jacobi_cg(1e-12), world);
  simulation::RunSummary summary;
  sim.advance_to(t_end, summary);
  const auto all = testkit::gather_particles(sim.particles(), world.comm());
  std::map<ParticleId, testkit::ParticleState> reference;
  if (MPI_Comm solo = testkit::solo_communicator(); solo != MPI_COMM_NULL) {
    simulation::Simulation solo_sim(testkit::sponge_scene(), testkit::jacobi_cg(1e-12), parallel::Communicator(solo));
    simulation::RunSummary solo_summary;
    solo_sim.advance_to(t_end, solo_summary);
    EXPECT_EQ(solo_summary.steps, summary.steps);
    reference = testkit::gather_particles(solo_sim.particles(), solo);
    MPI_Comm_free(&solo);
  }
  if (!world.is_root()) return;
  ASSERT_EQ(all.size(), reference.size());
  double dx = 0.0, dv = 0.0, dF = 0.0, db = 0.0, speed = 0.0;
  for (const auto& [id, s] : reference) {
    const auto it = all.find(id);
    ASSERT_NE(it, all.end()) << "particle " << id << " missing";
    dx = std::max(dx, (it->second.x - s.x).norm());
    dv = std::max(dv, (it->second.v - s.v).norm());
    dF = std::max(dF, (it->second.F - s.F).norm());
    db = std::max(db, (it->second.b - s.b).norm());
    speed = std::max(speed, s.v.norm());
  }
  EXPECT_GT(speed, 0.1);
  EXPECT_LT(dx, 1e-9);
  EXPECT_LT(dv, 1e-7 * speed);
  EXPECT_LT(dF, 1e-8);
  EXPECT_LT(db, 1e-8);
}
