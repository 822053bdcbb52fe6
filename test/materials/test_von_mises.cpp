// Von Mises plasticity (§4.2.6, §4.3) with the radial return mapping, driven by prescribed
// velocity gradients:
// - a plastic flow driven by pure shear is isochoric: J_P = det F_P = 1 (§4.3), while F = F_E F_P;
// - after each return the stress is on the yield surface (3/2 τ':τ')^{1/2} = Y + K ε;
// - in simple shear of a perfectly plastic material the shear stress rises as μγ until γ = Y/(√3 μ)
//   and then stays at the von Mises shear yield stress Y/√3 (small elastic strains, Y ≪ μ);
// - a hydrostatic compression never yields (τ' = 0).
#include <gtest/gtest.h>

#include <cmath>

#include "test_helpers.hpp"
#include "viscompm/materials/von_mises.hpp"

using namespace viscompm;
using namespace viscompm::materials;

namespace {
VonMisesParameters parameters(double yield, double hardening) {
  VonMisesParameters p;
  p.shear_modulus = 100.0;
  p.lame_lambda = 300.0;
  p.yield_stress = yield;
  p.hardening_modulus = hardening;
  return p;
}

Mat3 deviator(const Mat3& m) { return m - m.trace() / 3.0 * Mat3::Identity(); }
}  // namespace

TEST(VonMises, PlasticFlowDrivenByPureShearIsIsochoric) {
  const VonMises material("metal", parameters(5.0, 20.0));
  particles::ParticleSet ps;
  ps.add(0, Vec3::Zero(), Vec3::Zero(), 1.0, 1.0, 0);
  const Mat3 pure_shear = 2e-3 * Vec3(1.0, -1.0, 0.0).asDiagonal();  // isochoric to first order
  int plastic_steps = 0;
  for (int n = 0; n < 300; ++n) {
    material.update_state(ps, 0, pure_shear, {0.01});
    const Mat3& F = ps.deformation_gradient[0];
    const Mat3& F_E = ps.elastic_deformation_gradient[0];
    const Mat3& F_P = ps.plastic_deformation_gradient[0];
    EXPECT_NEAR(F_P.determinant(), 1.0, 1e-12) << "step " << n;  // J_P = 1 (§4.3)
    EXPECT_LT((F - F_E * F_P).norm(), 1e-13 * F.norm());
    if (ps.yield_function[0] > 0.0) {
      ++plastic_steps;
      // Back on the yield surface, with the hardened yield stress.
      const Mat3 tau_dev = material.parameters().shear_modulus * deviator(F_E * F_E.transpose());
      EXPECT_NEAR(std::sqrt(1.5) * tau_dev.norm(), 5.0 + 20.0 * ps.equivalent_plastic_strain[0], 1e-10);
    }
  }
  EXPECT_GT(plastic_steps, 250);
  EXPECT_GT(ps.equivalent_plastic_strain[0], 0.5);  // a large plastic flow, not a trace of one
  // The plastic part carries the stretch: F_P is far from a rotation.
  EXPECT_GT((ps.plastic_deformation_gradient[0] * ps.plastic_deformation_gradient[0].transpose() - Mat3::Identity()).norm(), 1.0);
}

TEST(VonMises, SimpleShearYieldsAtTheVonMisesShearStress) {
  const double mu = 100.0, yield = 0.5;  // Y/μ = 0.005: small elastic strains
  const VonMises material("metal", parameters(yield, 0.0));
  particles::ParticleSet ps;
  ps.add(0, Vec3::Zero(), Vec3::Zero(), 1.0, 1.0, 0);
  const double dgamma = 1e-4, onset = yield / (std::sqrt(3.0) * mu);
  Mat3 A = Mat3::Zero();
  A(0, 1) = dgamma;
  for (int n = 1; n <= 2000; ++n) {
    material.update_state(ps, 0, A, {0.01});
    const double gamma = n * dgamma;
    const Mat3& F_E = ps.elastic_deformation_gradient[0];
    const double J = F_E.determinant();
    const double tau_xy = mu * (F_E * F_E.transpose())(0, 1) / J;  // σ_xy of (5.9)
    if (gamma < 0.99 * onset) {
      EXPECT_NEAR(tau_xy, mu * gamma, 1e-9) << "elastic at γ = " << gamma;
      EXPECT_EQ(ps.equivalent_plastic_strain[0], 0.0);
    } else if (gamma > 1.5 * onset) {
      EXPECT_NEAR(tau_xy, yield / std::sqrt(3.0), 2e-3 * yield / std::sqrt(3.0)) << "plastic at γ = " << gamma;
    }
  }
  // The plastic shear strain is the total minus the elastic one: ε = (γ − γ_y)/√3 for simple shear.
  EXPECT_NEAR(ps.equivalent_plastic_strain[0], (2000 * dgamma - onset) / std::sqrt(3.0), 0.01 * 0.2);
}

TEST(VonMises, HydrostaticCompressionDoesNotYield) {
  const VonMises material("metal", parameters(0.1, 0.0));
  particles::ParticleSet ps;
  ps.add(0, Vec3::Zero(), Vec3::Zero(), 1.0, 1.0, 0);
  for (int n = 0; n < 50; ++n) material.update_state(ps, 0, -0.005 * Mat3::Identity(), {0.01});
  EXPECT_EQ(ps.equivalent_plastic_strain[0], 0.0);
  EXPECT_LT((ps.elastic_deformation_gradient[0] - ps.deformation_gradient[0]).norm(), 1e-15);
  EXPECT_LT(ps.deformation_gradient[0].determinant(), 0.8);
}

TEST(VonMises, UnloadingAfterYieldIsElastic) {
  const VonMises material("metal", parameters(1.0, 0.0));
  particles::ParticleSet ps;
  ps.add(0, Vec3::Zero(), Vec3::Zero(), 1.0, 1.0, 0);
  Mat3 A = Mat3::Zero();
  A(0, 1) = 1e-3;
  for (int n = 0; n < 30; ++n) material.update_state(ps, 0, A, {0.01});
  const double plastic = ps.equivalent_plastic_strain[0];
  ASSERT_GT(plastic, 0.0);
  for (int n = 0; n < 5; ++n) material.update_state(ps, 0, -A, {0.01});  // back off the surface
  EXPECT_EQ(ps.equivalent_plastic_strain[0], plastic);
  EXPECT_LT(ps.yield_function[0], 0.0);
}
