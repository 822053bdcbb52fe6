// Colliders in motion: rigid motions are consistent (the velocity is the time derivative of the
// placement), a sticky rotating collider imposes v = v0 + ω × (x − c) on its nodes, a belt its
// surface velocity, a nozzle its inflow velocity while it emits, and particle-based collisions
// keep particles from crossing thin or fast solids within a step.
#include <gtest/gtest.h>

#include <algorithm>

#include "test_helpers.hpp"
#include "viscompm/boundary/colliders.hpp"
#include "viscompm/particles/sampling.hpp"

using namespace viscompm;

namespace {
boundary::RigidMotion keyframed() {
  boundary::RigidMotion m;
  m.center = Vec3(0.5, 0.5, 0.5);
  m.keyframes = {{0.1, Vec3::Zero(), Vec3::Zero()},
                 {0.3, Vec3(0.2, 0.0, -0.1), Vec3(0.0, 1.0, 0.0)},
                 {0.6, Vec3(0.2, 0.3, -0.1), Vec3(0.4, 1.0, 0.2)}};
  return m;
}

// A layout covering the box [lo, hi] with particles (every node of it is in the layout).
grid::GridLayout layout_over(const grid::GridGeometry& g, const Vec3& lo, const Vec3& hi) {
  particles::BodySampling body;
  body.shape.lower = lo;
  body.shape.upper = hi;
  static particles::ParticleSet ps;
  ps = particles::ParticleSet();
  particles::sample_body(body, g, 0, [](const Vec3&) { return true; }, ps);
  return testkit::serial_layout(ps, g, grid::KernelOrder::quadratic);
}

grid::GridGeometry unit_grid() {
  grid::GridGeometry g;
  g.dx = 0.05;
  g.cells = Int3(20, 20, 20);
  return g;
}
}  // namespace

TEST(RigidMotion, VelocityIsTheTimeDerivativeOfThePlacement) {
  boundary::RigidMotion spinning;
  spinning.velocity = Vec3(0.3, -0.2, 0.1);
  spinning.angular_velocity = Vec3(0.5, 2.0, -1.0);
  spinning.center = Vec3(0.4, 0.5, 0.6);
  spinning.start_time = 0.05;
  spinning.stop_time = 0.5;
  const double h = 1e-6;
  for (const auto& motion : {spinning, keyframed()})
    for (double t : {0.0, 0.07, 0.15, 0.25, 0.4, 0.45, 0.7}) {
      const Vec3 X(0.7, 0.3, 0.45);  // a material point at rest
      const Vec3 x = motion.transform_at(t).apply(X);
      const Vec3 dxdt = (motion.transform_at(t + h).apply(X) - motion.transform_at(t - h).apply(X)) / (2 * h);
      EXPECT_LT((motion.velocity_at(x, t) - dxdt).norm(), 1e-6 * (1.0 + dxdt.norm())) << "t = " << t;
      EXPECT_LT((motion.transform_at(t).inverse(x) - X).norm(), 1e-12);
      EXPECT_NEAR(motion.transform_at(t).rotation.determinant(), 1.0, 1e-12);
    }
  // Keyframes are interpolated through: at a keyframe time the placement is the keyframe's.
  const auto key = keyframed();
  const auto T = key.transform_at(0.3);
  EXPECT_LT((T.translation - Vec3(0.2, 0.0, -0.1)).norm(), 1e-14);
  EXPECT_LT((T.rotation - boundary::rotation_matrix(Vec3(0.0, 1.0, 0.0))).norm(), 1e-12);
  // At rest before the start and after the stop, where it left off.
  EXPECT_EQ(spinning.velocity_at(Vec3::Zero(), 0.0), Vec3::Zero());
  EXPECT_EQ(spinning.velocity_at(Vec3::Zero(), 0.6), Vec3::Zero());
  EXPECT_LT((spinning.transform_at(0.9).translation - 0.45 * spinning.velocity).norm(), 1e-14);
}

TEST(Colliders, StickyRotatingColliderImposesTheRigidVelocityOnItsNodes) {
  const auto g = unit_grid();
  const auto layout = layout_over(g, Vec3(0.2, 0.2, 0.2), Vec3(0.8, 0.8, 0.8));
  boundary::Collider grip;
  grip.shape.lower = Vec3(0.3, 0.6, 0.3);
  grip.shape.upper = Vec3(0.7, 0.75, 0.7);
  grip.type = boundary::ContactType::sticky;
  grip.motion.velocity = Vec3(0.0, 0.1, 0.0);
  grip.motion.angular_velocity = Vec3(0.0, 3.0, 0.0);
  grip.motion.center = Vec3(0.5, 0.0, 0.5);
  boundary::DomainWalls walls;
  walls.thickness = 1;
  const boundary::Boundary b({grip}, walls);
  const double t = 0.2;
  const NodeVectorField trial(layout.local_node_count(), Vec3(1.0, 2.0, 3.0));
  const auto c = b.constrain(layout, t, trial);
  const auto T = grip.transform_at(t);
  std::size_t inside = 0;
  for (std::size_t i = 0; i < layout.local_node_count(); ++i) {
    const Vec3 x = g.node_position(layout.nodes[i]);
    if (grip.shape.signed_distance(T.inverse(x)) < -1e-9) {
      ++inside;
      const Vec3 expected = Vec3(0.0, 0.1, 0.0) + Vec3(0.0, 3.0, 0.0).cross(x - Vec3(0.5, 0.1 * t, 0.5));
      EXPECT_EQ(c.projection[i], Mat3::Zero());
      EXPECT_LT((c.prescribed[i] - expected).norm(), 1e-12) << x.transpose();
    } else if (grip.shape.signed_distance(T.inverse(x)) > 1e-9) {
      EXPECT_EQ(c.projection[i], Mat3::Identity()) << x.transpose();
    }
  }
  EXPECT_GT(inside, 20u);
}

TEST(Colliders, ABeltImposesItsSurfaceVelocityAndANozzleItsInflow) {
  const auto g = unit_grid();
  const auto layout = layout_over(g, Vec3(0.2, 0.2, 0.2), Vec3(0.8, 0.8, 0.8));
  boundary::Collider belt;
  belt.shape.lower = Vec3(0.0, 0.0, 0.0);
  belt.shape.upper = Vec3(1.0, 0.3, 1.0);
  belt.surface_velocity = Vec3(0.4, 0.0, 0.0);
  boundary::Inflow nozzle;
  nozzle.nozzle.kind = Shape::Kind::cylinder;
  nozzle.nozzle.center = Vec3(0.5, 0.7, 0.5);
  nozzle.nozzle.axis = Vec3::UnitY();
  nozzle.nozzle.radius = 0.08;
  nozzle.nozzle.length = 0.1;
  nozzle.velocity = Vec3(0.0, -1.5, 0.0);
  nozzle.start_time = 0.1;
  nozzle.stop_time = 0.3;
  boundary::DomainWalls walls;
  walls.thickness = 1;
  const boundary::Boundary b({belt}, walls, {nozzle});
  const NodeVectorField trial(layout.local_node_count(), Vec3::Zero());
  for (double t : {0.05, 0.2, 0.35}) {
    const auto c = b.constrain(layout, t, trial);
    std::size_t on_belt = 0, in_nozzle = 0;
    for (std::size_t i = 0; i < layout.local_node_count(); ++i) {
      const Vec3 x = g.node_position(layout.nodes[i]);
      const double below_top = 0.3 - x.y();
      if (below_top >= -1e-9 && below_top < std::min({x.x(), 1.0 - x.x(), x.z(), 1.0 - x.z(), x.y()}) - 1e-9) {
        ++on_belt;
        // The belt is at rest; its surface moves along x: nodes nearest its top face (normal +y)
        // move with the whole surface velocity.
        EXPECT_LT((c.prescribed[i] - Vec3(0.4, 0.0, 0.0)).norm(), 1e-9) << x.transpose();
      }
      if (nozzle.nozzle.signed_distance(x) < -1e-9) {
        ++in_nozzle;
        if (t > 0.1 && t < 0.3) {
          EXPECT_EQ(c.projection[i], Mat3::Zero());
          EXPECT_EQ(c.prescribed[i], nozzle.velocity);
        } else {
          EXPECT_EQ(c.projection[i], Mat3::Identity());
        }
      }
    }
    EXPECT_GT(on_belt, 10u);
    EXPECT_GT(in_nozzle, 0u);
  }
}

TEST(ParticleCollisions, ThinAndFastSolidsAreNotCrossedWithinAStep) {
  // A slip plate 1 mm thick (a cell is 5 cm): no node lies inside it.
  boundary::Collider plate;
  plate.shape.lower = Vec3(0.0, 0.0, 0.5);
  plate.shape.upper = Vec3(1.0, 1.0, 0.501);
  plate.type = boundary::ContactType::slip;
  boundary::Collider bullet;
  bullet.shape.kind = Shape::Kind::sphere;
  bullet.shape.center = Vec3(0.2, 0.5, 0.2);
  bullet.shape.radius = 0.05;
  bullet.type = boundary::ContactType::separating;
  bullet.motion.velocity = Vec3(20.0, 0.0, 0.0);
  boundary::Collider grip;
  grip.shape.lower = Vec3(0.8, 0.8, 0.0);
  grip.shape.upper = Vec3(0.9, 0.9, 0.1);
  grip.type = boundary::ContactType::sticky;
  grip.motion.angular_velocity = Vec3(0.0, 0.0, 2.0);
  grip.motion.center = Vec3(0.85, 0.85, 0.0);
  const boundary::Boundary b({plate, bullet, grip}, boundary::DomainWalls{});
  const double t = 0.0, dt = 0.01;
  std::vector<Vec3> x = {Vec3(0.3, 0.3, 0.45),    // crosses the plate: normal velocity removed
                         Vec3(0.3, 0.3, 0.45),    // moves away from the plate: untouched
                         Vec3(0.42, 0.5, 0.2),    // at rest, the bullet sweeps over it this step
                         Vec3(0.86, 0.85, 0.05),  // inside the spinning grip: takes its velocity
                         Vec3(0.3, 0.8, 0.3)};    // far from everything
  std::vector<Vec3> v = {Vec3(1.0, 0.5, 20.0), Vec3(1.0, 0.5, -20.0), Vec3::Zero(), Vec3(1.0, 1.0, 1.0),
                         Vec3(0.1, 0.2, 0.3)};
  const auto v_before = v;
  EXPECT_EQ(b.collide_particles(x, v, t, dt), 3u);
  EXPECT_LT((v[0] - Vec3(1.0, 0.5, 0.0)).norm(), 1e-9);
  EXPECT_EQ(v[1], v_before[1]);
  EXPECT_GT(v[2].x(), 0.0);  // pushed along by the bullet: no longer approaching it
  const Vec3 n = (x[2] - bullet.shape.center).normalized();
  EXPECT_GE((v[2] - bullet.motion.velocity).dot(n), -1e-9);
  EXPECT_LT((v[3] - Vec3(0.0, 0.0, 2.0).cross(x[3] - Vec3(0.85, 0.85, 0.0))).norm(), 1e-12);
  EXPECT_EQ(v[4], v_before[4]);
  // The projected paths stay out of the plate.
  EXPECT_LE((x[0] + dt * v[0]).z(), 0.5);
}
