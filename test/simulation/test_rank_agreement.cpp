// 20 steps of the default scene (inputs/scenes/shooting_sponge.xml, with tight solver
// tolerances and rebalancing on) agree between N ranks and one: positions to 1e-8 relative to
// the domain. On one rank, two runs are identical bit for bit.
#include <gtest/gtest.h>

#include "gather.hpp"
#include "scenes.hpp"
#include "viscompm/simulation/simulation.hpp"

using namespace viscompm;

namespace {
std::map<ParticleId, testkit::ParticleState> twenty_steps(const parallel::Communicator& comm, std::int64_t& steps) {
  const auto scene = scene::read_scene(VISCOMPM_SOURCE_DIR "/inputs/scenes/shooting_sponge.xml",
                                       {{"Newton/Tolerance", "1e-10"}, {"Grid/Rebalance threshold", "1.1"},
                                        {"Simulation/Max time step", "2e-3"}});
  simulation::Simulation sim(scene, testkit::jacobi_cg(1e-12), comm);
  simulation::RunSummary summary;
  sim.advance_to(20 * 2e-3, summary);  // 20 steps of the Δt cap
  steps = summary.steps;
  return testkit::gather_particles(sim.particles(), comm.comm());
}
}  // namespace

TEST(RankAgreement, TwentyStepsOfTheDefaultSceneAgreeWithOneRank) {
  const parallel::Communicator world(MPI_COMM_WORLD);
  std::int64_t steps = 0, reference_steps = 0;
  const auto all = twenty_steps(world, steps);
  EXPECT_EQ(steps, 20);
  std::map<ParticleId, testkit::ParticleState> reference;
  if (MPI_Comm solo = testkit::solo_communicator(); solo != MPI_COMM_NULL) {
    reference = twenty_steps(parallel::Communicator(solo), reference_steps);
    MPI_Comm_free(&solo);
  }
  if (!world.is_root()) return;
  EXPECT_EQ(reference_steps, steps);
  const double domain = 1.2;
  double worst_position = 0.0, speed = 0.0;
  for (const auto& [id, s] : reference) {
    const auto it = all.find(id);
    ASSERT_NE(it, all.end());
    worst_position = std::max(worst_position, (it->second.x - s.x).norm());
    speed = std::max(speed, s.v.norm());
  }
  EXPECT_GT(speed, 0.1);  // the bullet has hit the sponge
  EXPECT_LT(worst_position / domain, 1e-8);
  if (world.size() == 1) EXPECT_TRUE(testkit::bitwise_equal(all, reference));
}
