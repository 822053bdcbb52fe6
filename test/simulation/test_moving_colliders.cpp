// Colliders in whole runs, on 1 and 2 ranks: a block glued to a sticky rotating grip turns with it
// rigidly; a belt (a sticky box at rest whose surface moves) carries a block resting on it at the
// belt's speed; particles thrown at a slip plate thinner than a cell, between grid nodes, do not
// cross it (particle-based collisions, §5.5.1).
#include <gtest/gtest.h>

#include <cmath>

#include "gather.hpp"
#include "scenes.hpp"
#include "viscompm/boundary/rigid_motion.hpp"
#include "viscompm/simulation/simulation.hpp"

using namespace viscompm;

TEST(MovingColliders, ABlockGluedToARotatingGripTurnsRigidly) {
  auto scene = testkit::base_scene(Vec3(1.0, 1.0, 1.0), 0.05);
  scene.simulation.max_time_step = 5e-3;
  scene.simulation.cfl = 0.5;
  scene.newton.tolerance = 1e-8;
  // A stiff, elastic block whose lower part sits in the grip.
  scene.materials.push_back(testkit::oldroyd_b_material("stiff", 1.0, 4000.0, 16000.0, 0.0, "paper", 1e30));
  scene.bodies.push_back(testkit::box_body("stiff", Vec3(0.4, 0.2, 0.4), Vec3(0.6, 0.55, 0.6), Vec3::Zero()));
  auto grip = testkit::box_collider("grip", boundary::ContactType::sticky, Vec3(0.35, 0.1, 0.35), Vec3(0.65, 0.3, 0.65));
  grip.angular_velocity = Vec3(0.0, 2.0, 0.0);
  grip.rotation_center = Vec3(0.5, 0.0, 0.5);
  scene.colliders.push_back(grip);
  const parallel::Communicator comm(MPI_COMM_WORLD);
  simulation::Simulation sim(scene, testkit::jacobi_cg(1e-10), comm);
  const auto start = testkit::gather_particles(sim.particles(), comm.comm());
  const double t = 0.25;  // half a radian
  simulation::RunSummary summary;
  sim.advance_to(t, summary);
  const auto end = testkit::gather_particles(sim.particles(), comm.comm());
  ASSERT_EQ(end.size(), start.size());
  const Mat3 R = boundary::rotation_matrix(Vec3(0.0, 2.0 * t, 0.0));
  const Vec3 c(0.5, 0.0, 0.5);
  double worst = 0.0, travelled = 0.0;
  for (const auto& [id, s] : start) {
    const Vec3 rigid = R * (s.x - c) + c;
    worst = std::max(worst, (end.at(id).x - rigid).norm());
    travelled = std::max(travelled, (rigid - s.x).norm());
    // The velocity too: ω × (x − c).
    const Vec3 v_rigid = Vec3(0.0, 2.0, 0.0).cross(end.at(id).x - c);
    EXPECT_LT((end.at(id).v - v_rigid).norm(), 0.05 * v_rigid.norm() + 1e-3) << "particle " << id;
  }
  // The particles travelled up to ~7 cm; they stay on the rigid placement within 2 mm.
  EXPECT_GT(travelled, 0.06);
  EXPECT_LT(worst, 0.002) << "largest distance from the rigid placement";
}

TEST(MovingColliders, ABeltCarriesABlockRestingOnItAtTheBeltSpeed) {
  auto scene = testkit::base_scene(Vec3(1.2, 0.6, 0.5), 0.04);
  scene.simulation.gravity = Vec3(0.0, -9.81, 0.0);
  scene.simulation.max_time_step = 4e-3;
  scene.newton.tolerance = 1e-8;
  scene.materials.push_back(testkit::oldroyd_b_material("block", 1.0, 500.0, 2000.0, 0.0, "paper", 1e30));
  scene.bodies.push_back(testkit::box_body("block", Vec3(0.2, 0.2, 0.15), Vec3(0.4, 0.32, 0.35), Vec3::Zero()));
  auto belt = testkit::box_collider("belt", boundary::ContactType::sticky, Vec3(-0.1, -0.1, -0.1), Vec3(1.3, 0.2, 0.6));
  belt.surface_velocity = Vec3(0.5, 0.0, 0.0);
  scene.colliders.push_back(belt);
  const parallel::Communicator comm(MPI_COMM_WORLD);
  simulation::Simulation sim(scene, testkit::jacobi_cg(1e-10), comm);
  simulation::RunSummary summary;
  sim.advance_to(0.4, summary);
  const auto end = testkit::gather_particles(sim.particles(), comm.comm());
  Vec3 mean_velocity = Vec3::Zero();
  double lowest = 1.0;
  for (const auto& [id, s] : end) {
    mean_velocity += s.v;
    lowest = std::min(lowest, s.x.y());
  }
  mean_velocity /= static_cast<double>(end.size());
  EXPECT_NEAR(mean_velocity.x(), 0.5, 0.025) << mean_velocity.transpose();
  EXPECT_NEAR(mean_velocity.y(), 0.0, 0.025);
  EXPECT_NEAR(mean_velocity.z(), 0.0, 0.01);
  EXPECT_GT(lowest, 0.17);  // it rests on the belt (top at 0.2), not in it
}

TEST(MovingColliders, ParticlesThrownAtAThinSlipPlateDoNotCrossIt) {
  auto scene = testkit::base_scene(Vec3(0.6, 0.6, 1.0), 0.05);
  scene.simulation.max_time_step = 4e-3;
  scene.newton.tolerance = 1e-6;
  scene.materials.push_back(testkit::oldroyd_b_material("goo", 1.0, 20.0, 100.0, 0.0, "paper", 0.1));
  scene.bodies.push_back(testkit::box_body("goo", Vec3(0.2, 0.2, 0.25), Vec3(0.4, 0.4, 0.4), Vec3(0.0, 0.0, 4.0)));
  // 1 cm thick, between the node planes z = 0.5 and 0.55: no node lies inside it.
  scene.colliders.push_back(testkit::box_collider("plate", boundary::ContactType::slip, Vec3(-0.1, -0.1, 0.51), Vec3(0.7, 0.7, 0.52)));
  const parallel::Communicator comm(MPI_COMM_WORLD);
  simulation::Simulation sim(scene, testkit::jacobi_cg(1e-8), comm);
  simulation::RunSummary summary;
  double highest = 0.0;
  for (int k = 1; k <= 6; ++k) {  // unhindered the block would be 0.6 m further on
    sim.advance_to(0.025 * k, summary);
    for (const Vec3& x : sim.particles().position) highest = std::max(highest, x.z());
  }
  highest = comm.max(highest);
  EXPECT_LT(highest, 0.51);
  EXPECT_GT(highest, 0.45);  // it did reach the plate
}
