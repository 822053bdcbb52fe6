// Emitters on 1 and 2 ranks: the delivered mass is the prescribed rate times the time (to within
// one layer), emitted particles leave at the prescribed velocity, ids stay unique across ranks
// and across a restart in the middle of the emission, which continues bit for bit.
#include <gtest/gtest.h>

#include <filesystem>

#include "gather.hpp"
#include "scenes.hpp"
#include "viscompm/simulation/simulation.hpp"

using namespace viscompm;

namespace {
scene::EmitterSettings nozzle(const std::string& name, const Vec3& centre, const Vec3& velocity, double rate) {
  scene::EmitterSettings e;
  e.name = name;
  e.shape = scene::ShapeKind::cylinder;
  e.center = centre;
  e.axis = velocity.normalized();
  e.radius = 0.08;
  e.length = 0.1;
  e.material = "goo";
  e.velocity = velocity;
  e.mass_rate = rate;
  e.start_time = 0.01;
  e.stop_time = 0.2;
  return e;
}

scene::SceneConfig emitter_scene() {
  auto scene = testkit::base_scene(Vec3(1.0, 1.0, 0.6), 0.05);
  scene.simulation.max_time_step = 4e-3;
  scene.simulation.cfl = 0.5;
  scene.newton.tolerance = 1e-10;
  scene.materials.push_back(testkit::oldroyd_b_material("goo", 2.0, 20.0, 100.0, 0.01, "paper", 0.5));
  scene.bodies.push_back(testkit::box_body("goo", Vec3(0.1, 0.1, 0.2), Vec3(0.3, 0.3, 0.4), Vec3::Zero()));
  scene.emitters.push_back(nozzle("down", Vec3(0.75, 0.8, 0.3), Vec3(0.0, -2.0, 0.0), 0.0));  // a stream
  scene.emitters.push_back(nozzle("sideways", Vec3(0.15, 0.5, 0.3), Vec3(1.5, 0.0, 0.0), 0.05));  // 0.05 kg/s
  return scene;
}

double total_mass(const particles::ParticleSet& ps, const parallel::Communicator& comm) {
  double m = 0.0;
  for (double mp : ps.mass) m += mp;
  return comm.sum(m);
}

}  // namespace

TEST(Emitters, DeliverThePrescribedMassAtThePrescribedVelocity) {
  const parallel::Communicator comm(MPI_COMM_WORLD);
  const auto scene = emitter_scene();
  simulation::Simulation sim(scene, testkit::jacobi_cg(1e-10), comm);
  const double body_mass = total_mass(sim.particles(), comm);
  ASSERT_EQ(sim.emitters().size(), 2u);
  simulation::RunSummary summary;
  for (double t : {0.05, 0.1, 0.15}) {
    sim.advance_to(t, summary);
    // The particles present are the body's and the emitters' exactly.
    EXPECT_NEAR(total_mass(sim.particles(), comm), body_mass + sim.emitted_mass(), 1e-12 * body_mass);
    const auto& stream = sim.emitters()[0];
    const auto& side = sim.emitters()[1];
    const double layer_stream = stream.particle_mass() * stream.layer_size();
    const double layer_side = side.particle_mass() * side.layer_size();
    // A stream: ρ · (cross-section of the lattice) · |v|.
    const double h = scene.grid.cell_size / 2, rate_stream = 2.0 * stream.layer_size() * h * h * 2.0;
    EXPECT_NEAR(stream.delivered_mass(), rate_stream * (t - 0.01), layer_stream + 1e-12) << "t = " << t;
    EXPECT_NEAR(side.delivered_mass(), 0.05 * (t - 0.01), layer_side + 1e-12) << "t = " << t;
    EXPECT_GT(side.delivered_mass(), 0.0);
  }
  // No forces on the free jets (no gravity, apart from each other and from the body): they keep
  // the inflow velocity.
  const auto all = testkit::gather_particle_set(sim.particles(), comm.comm());
  Vec3 down_mean = Vec3::Zero(), side_mean = Vec3::Zero();
  int down = 0, side = 0;
  for (std::size_t p = 0; p < all.size(); ++p) {
    if (all.position[p].x() > 0.6) {
      down_mean += all.velocity[p];
      ++down;
      EXPECT_LT((all.velocity[p] - Vec3(0.0, -2.0, 0.0)).norm(), 0.1);
    } else if (all.position[p].y() > 0.38) {
      side_mean += all.velocity[p];
      ++side;
      EXPECT_LT((all.velocity[p] - Vec3(1.5, 0.0, 0.0)).norm(), 0.1);
    }
  }
  ASSERT_GT(down, 50);
  ASSERT_GT(side, 10);
  EXPECT_LT((down_mean / down - Vec3(0.0, -2.0, 0.0)).norm(), 0.02);
  EXPECT_LT((side_mean / side - Vec3(1.5, 0.0, 0.0)).norm(), 0.02);
  testkit::gather_particles(sim.particles(), comm.comm());  // throws on a duplicate id
}

TEST(Emitters, ARestartInTheMiddleOfTheEmissionContinuesBitForBitWithUniqueIds) {
  const parallel::Communicator comm(MPI_COMM_WORLD);
  auto scene = emitter_scene();
  scene.output.directory = testkit::work_directory(comm, "emitter_restart");
  const auto solver = testkit::jacobi_cg(1e-12);
  simulation::Simulation straight(scene, solver, comm);
  simulation::RunSummary summary;
  straight.advance_to(0.06, summary);
  const std::string checkpoint = straight.write_checkpoint();
  straight.advance_to(0.12, summary);
  const auto reference = testkit::gather_particles(straight.particles(), comm.comm());  // unique ids

  simulation::Simulation restarted(scene, solver, comm, checkpoint);
  for (std::size_t k = 0; k < 2; ++k)
    EXPECT_LT(restarted.emitters()[k].layers_emitted(), straight.emitters()[k].layers_emitted());
  restarted.advance_to(0.12, summary);
  const auto continued = testkit::gather_particles(restarted.particles(), comm.comm());  // unique ids
  EXPECT_EQ(continued.size(), reference.size());
  EXPECT_TRUE(testkit::bitwise_equal(reference, continued))
      << "difference " << testkit::max_state_difference(reference, continued);
  for (std::size_t k = 0; k < 2; ++k)
    EXPECT_EQ(restarted.emitters()[k].layers_emitted(), straight.emitters()[k].layers_emitted());
  EXPECT_EQ(restarted.emitted_mass(), straight.emitted_mass());
}

// Issue 17, class 7: when layers leave faster than Δt, the layers due within a step appear by its
// end — before a frame at that time is written — so the delivered mass never lags the rate by
// more than the one layer doc/scenes.md allows (it lagged by about rate·Δt, 8 layers here).
TEST(Emitters, LayersDueWithinAStepAreEmittedByItsEnd) {
  const parallel::Communicator comm(MPI_COMM_WORLD);
  auto scene = testkit::base_scene(Vec3(1.0, 1.0, 0.6), 0.05);
  scene.simulation.max_time_step = 4e-3;
  scene.newton.tolerance = 1e-8;
  scene.materials.push_back(testkit::oldroyd_b_material("goo", 2.0, 20.0, 100.0, 0.01, "paper", 0.5));
  scene.bodies.push_back(testkit::box_body("goo", Vec3(0.7, 0.1, 0.2), Vec3(0.8, 0.2, 0.3), Vec3::Zero()));
  scene.emitters.push_back(nozzle("fast", Vec3(0.15, 0.5, 0.3), Vec3(1.5, 0.0, 0.0), 2.0));  // 2 kg/s
  simulation::Simulation sim(scene, testkit::jacobi_cg(1e-8), comm);
  const double body_mass = total_mass(sim.particles(), comm);
  const auto& emitter = sim.emitters()[0];
  const double layer = emitter.particle_mass() * emitter.layer_size();
  ASSERT_LT(emitter.layer_interval(), 0.25 * scene.simulation.max_time_step);  // several layers per step
  simulation::RunSummary summary;
  for (double t : {0.02, 0.05}) {
    sim.advance_to(t, summary);
    const double owed = 2.0 * (t - 0.01);  // rate × time since the start
    EXPECT_GE(sim.emitted_mass(), owed - 1e-12) << "t = " << t;
    EXPECT_LE(sim.emitted_mass(), owed + layer + 1e-12) << "t = " << t;
    EXPECT_NEAR(total_mass(sim.particles(), comm), body_mass + sim.emitted_mass(), 1e-12);
  }
  EXPECT_GT(summary.steps, 5);
}
