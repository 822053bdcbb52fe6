// Transfers conserve mass and momentum (§3.1) and APIC conserves angular momentum (Jiang et al.
// 2015), in both directions, for both kernels.
#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "test_helpers.hpp"
#include "viscompm/transfer/transfer.hpp"

using namespace viscompm;
using grid::KernelOrder;

namespace {
struct Fixture {
  grid::GridGeometry geometry;
  particles::ParticleSet particles;
  grid::GridLayout layout;

  Fixture(KernelOrder order, bool affine) {
    geometry.origin = Vec3(-0.5, 0.0, 0.25);
    geometry.dx = 0.1;
    geometry.cells = Int3(12, 10, 14);
    for (int p = 0; p < 300; ++p) {
      const Vec3 x = geometry.origin + Vec3(testkit::uniform(3, 9), testkit::uniform(3, 7), testkit::uniform(3, 11)) * geometry.dx;
      const Vec3 v(testkit::uniform(-1, 1), testkit::uniform(-1, 1), testkit::uniform(-1, 1));
      particles.add(p, x, v, testkit::uniform(0.5, 2.0), 1e-3, 0);
      if (affine) particles.affine_velocity.back() = testkit::random_matrix(3.0);
    }
    layout = testkit::serial_layout(particles, geometry, order);
  }
};

// Σ_p m_p (x_p × v_p + d Δx² ε:C_pᵀ): a particle's angular momentum under APIC.
Vec3 particle_angular_momentum(const particles::ParticleSet& ps, double inertia) {
  Vec3 L = Vec3::Zero();
  for (std::size_t p = 0; p < ps.size(); ++p) {
    const Mat3& C = ps.affine_velocity[p];
    const Vec3 spin(C(2, 1) - C(1, 2), C(0, 2) - C(2, 0), C(1, 0) - C(0, 1));
    L += ps.mass[p] * (ps.position[p].cross(ps.velocity[p]) + inertia * spin);
  }
  return L;
}

Vec3 grid_angular_momentum(const grid::GridLayout& layout, const NodeScalarField& m, const NodeVectorField& v) {
  Vec3 L = Vec3::Zero();
  for (std::size_t i = 0; i < m.size(); ++i) L += layout.geometry.node_position(layout.nodes[i]).cross(m[i] * v[i]);
  return L;
}
}  // namespace

class Transfer : public ::testing::TestWithParam<KernelOrder> {};

TEST_P(Transfer, ParticlesToGridConservesMassMomentumAndApicAngularMomentum) {
  Fixture f(GetParam(), true);
  NodeScalarField m;
  NodeVectorField mv;
  transfer::particles_to_grid(f.particles, f.layout, transfer::Scheme::apic, m, mv);
  double mass_p = 0.0, mass_i = 0.0;
  Vec3 momentum_p = Vec3::Zero(), momentum_i = Vec3::Zero();
  for (std::size_t p = 0; p < f.particles.size(); ++p) {
    mass_p += f.particles.mass[p];
    momentum_p += f.particles.mass[p] * f.particles.velocity[p];
  }
  for (std::size_t i = 0; i < m.size(); ++i) {
    mass_i += m[i];
    momentum_i += mv[i];
  }
  EXPECT_NEAR(mass_i, mass_p, 1e-12 * mass_p);
  EXPECT_LT((momentum_i - momentum_p).norm(), 1e-12 * mass_p);
  const double inertia = grid::apic_inertia_factor(GetParam()) * f.geometry.dx * f.geometry.dx;
  const Vec3 L_p = particle_angular_momentum(f.particles, inertia);
  const Vec3 L_i = grid_angular_momentum(f.layout, m, transfer::grid_velocity(m, mv));
  EXPECT_LT((L_i - L_p).norm(), 1e-11 * L_p.norm()) << L_i.transpose() << " vs " << L_p.transpose();
}

TEST_P(Transfer, GridToParticlesConservesMomentumAndApicAngularMomentum) {
  Fixture f(GetParam(), true);
  NodeScalarField m;
  NodeVectorField mv;
  transfer::particles_to_grid(f.particles, f.layout, transfer::Scheme::apic, m, mv);
  const NodeVectorField v_old = transfer::grid_velocity(m, mv);
  NodeVectorField v_new(v_old.size());
  for (auto& v : v_new) v = Vec3(testkit::uniform(-2, 2), testkit::uniform(-2, 2), testkit::uniform(-2, 2));
  transfer::grid_to_particles(f.particles, f.layout, {transfer::Scheme::apic, 0.0}, v_new, v_old, 1e-3);
  Vec3 momentum_p = Vec3::Zero(), momentum_i = Vec3::Zero();
  for (std::size_t p = 0; p < f.particles.size(); ++p) momentum_p += f.particles.mass[p] * f.particles.velocity[p];
  for (std::size_t i = 0; i < m.size(); ++i) momentum_i += m[i] * v_new[i];
  EXPECT_LT((momentum_i - momentum_p).norm(), 1e-12 * momentum_i.norm());
  const double inertia = grid::apic_inertia_factor(GetParam()) * f.geometry.dx * f.geometry.dx;
  const Vec3 L_p = particle_angular_momentum(f.particles, inertia);
  const Vec3 L_i = grid_angular_momentum(f.layout, m, v_new);
  EXPECT_LT((L_i - L_p).norm(), 1e-11 * L_i.norm());
}

TEST_P(Transfer, PicFlipBlendConservesMomentum) {
  Fixture f(GetParam(), false);
  NodeScalarField m;
  NodeVectorField mv;
  transfer::particles_to_grid(f.particles, f.layout, transfer::Scheme::pic_flip, m, mv);
  const NodeVectorField v_old = transfer::grid_velocity(m, mv);
  NodeVectorField v_new = v_old;
  for (auto& v : v_new) v += Vec3(testkit::uniform(-1, 1), testkit::uniform(-1, 1), testkit::uniform(-1, 1));
  transfer::grid_to_particles(f.particles, f.layout, {transfer::Scheme::pic_flip, 0.7}, v_new, v_old, 1e-3);
  Vec3 momentum_p = Vec3::Zero(), momentum_i = Vec3::Zero();
  for (std::size_t p = 0; p < f.particles.size(); ++p) momentum_p += f.particles.mass[p] * f.particles.velocity[p];
  for (std::size_t i = 0; i < m.size(); ++i) momentum_i += m[i] * v_new[i];
  EXPECT_LT((momentum_i - momentum_p).norm(), 1e-12 * (1.0 + momentum_i.norm()));
}

TEST_P(Transfer, ApicRoundTripReproducesAffineVelocityFields) {
  // An affine field v(x) = b + G x survives p2g → g2p exactly with APIC (C_p = G).
  Fixture f(GetParam(), false);
  const Vec3 b(0.3, -0.2, 0.5);
  const Mat3 G = testkit::random_matrix(1.0);
  for (std::size_t p = 0; p < f.particles.size(); ++p) {
    f.particles.velocity[p] = b + G * f.particles.position[p];
    f.particles.affine_velocity[p] = G;
  }
  NodeScalarField m;
  NodeVectorField mv;
  transfer::particles_to_grid(f.particles, f.layout, transfer::Scheme::apic, m, mv);
  const NodeVectorField v = transfer::grid_velocity(m, mv);
  const auto A = transfer::grid_to_particles(f.particles, f.layout, {transfer::Scheme::apic, 0.0}, v, v, 0.01);
  for (std::size_t p = 0; p < f.particles.size(); ++p) {
    EXPECT_LT((f.particles.velocity[p] - (b + G * f.particles.position[p])).norm(), 1e-12);
    EXPECT_LT((f.particles.affine_velocity[p] - G).norm(), 1e-11);
    EXPECT_LT((A[p] - 0.01 * G).norm(), 1e-12);  // A_p = Δt ∇v
  }
}

INSTANTIATE_TEST_SUITE_P(Orders, Transfer, ::testing::Values(KernelOrder::quadratic, KernelOrder::cubic),
                         [](const auto& info) { return grid::kernel_name(info.param); });
