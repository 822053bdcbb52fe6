// Particles that reach the edge of the grid are deleted and counted, or held at the last cell,
// as Grid/Outside particles says; nothing is lost or duplicated otherwise.
#include <gtest/gtest.h>

#include "gather.hpp"
#include "scenes.hpp"
#include "viscompm/simulation/simulation.hpp"

using namespace viscompm;

namespace {
// A block thrown at the upper x face with walls that let it through (slip along x is not
// constrained by y/z walls: the x walls are set to the thinnest layer and separating).
std::pair<std::int64_t, std::int64_t> throw_at_the_wall(scene::OutsideParticles mode, std::int64_t& deleted) {
  auto scene = testkit::base_scene(Vec3(1.0, 0.6, 0.6), 0.05);
  scene.grid.outside_particles = mode;
  scene.grid.walls = boundary::ContactType::slip;
  scene.grid.wall_thickness = 1;
  scene.materials.push_back(testkit::oldroyd_b_material("goo", 1.0, 1.0, 5.0, 0.0, "physical", 0.01));
  scene.bodies.push_back(testkit::box_body("goo", Vec3(0.5, 0.2, 0.2), Vec3(0.8, 0.4, 0.4), Vec3(8.0, 0, 0)));
  scene.newton.tolerance = 1e-6;
  const parallel::Communicator comm(MPI_COMM_WORLD);
  simulation::Simulation sim(scene, testkit::jacobi_cg(1e-8), comm);
  const auto before = comm.sum(static_cast<std::int64_t>(sim.particles().size()));
  simulation::RunSummary summary;
  sim.advance_to(0.08, summary);
  deleted = summary.particles_deleted;
  testkit::gather_particles(sim.particles(), comm.comm());  // throws on duplicates
  return {before, comm.sum(static_cast<std::int64_t>(sim.particles().size()))};
}
}  // namespace

TEST(OutsideParticles, DeletedAndCountedOrClamped) {
  std::int64_t deleted = 0;
  const auto [before_delete, after_delete] = throw_at_the_wall(scene::OutsideParticles::remove, deleted);
  EXPECT_GT(deleted, 0);
  EXPECT_EQ(after_delete, before_delete - deleted);
  const auto [before_clamp, after_clamp] = throw_at_the_wall(scene::OutsideParticles::clamp, deleted);
  EXPECT_EQ(deleted, 0);
  EXPECT_EQ(after_clamp, before_clamp);
}
