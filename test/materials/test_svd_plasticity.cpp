// SVD-clamped plasticity (§4.4) with hardening (§4.5.1) and softening (§4.5.2), driven by
// prescribed velocity gradients:
// - the singular values of F_E stay in [1 − c, 1 + s] and F = F_E F_P holds to rounding;
// - under plastic compression J_P falls below 1, and μ, λ rise for ζ > 0 and fall for ζ < 0, by
//   the factor e^{ζ(1 − J_P)} — measured through the energy of a probe deformation.
#include <gtest/gtest.h>

#include <Eigen/SVD>

#include "test_helpers.hpp"
#include "viscompm/materials/svd_plasticity.hpp"

using namespace viscompm;
using namespace viscompm::materials;

namespace {
SvdPlasticityParameters parameters(double zeta) {
  SvdPlasticityParameters p;
  p.shear_modulus = 100.0;
  p.lame_lambda = 200.0;
  p.critical_compression = 0.05;
  p.critical_stretch = 0.02;
  p.hardening = zeta;
  return p;
}
}  // namespace

TEST(SvdPlasticity, ElasticSingularValuesStayInTheClampRangeAndFIsFeFp) {
  const SvdPlasticity material("snow", parameters(10.0));
  particles::ParticleSet ps;
  ps.add(0, Vec3::Zero(), Vec3::Zero(), 1.0, 1.0, 0);
  int clamped_steps = 0;
  for (int n = 0; n < 2000; ++n) {
    Mat3 A;
    do A = testkit::random_matrix(0.15);
    while ((Mat3::Identity() + A).determinant() < 0.5);
    material.update_state(ps, 0, A, {0.01});
    const Vec3 sigma = Eigen::JacobiSVD<Mat3>(ps.elastic_deformation_gradient[0]).singularValues();
    EXPECT_GE(sigma.minCoeff(), 0.95 - 1e-14) << "step " << n;
    EXPECT_LE(sigma.maxCoeff(), 1.02 + 1e-14) << "step " << n;
    const Mat3& F = ps.deformation_gradient[0];
    EXPECT_LT((F - ps.elastic_deformation_gradient[0] * ps.plastic_deformation_gradient[0]).norm(), 1e-13 * F.norm())
        << "step " << n;
    clamped_steps += ps.yield_function[0] > 0.0;
    // Keep F bounded over 2000 random steps: restart the plastic history now and then (F = F_E,
    // F_P = I), which keeps F = F_E F_P.
    if (F.norm() > 1e3 || F.norm() < 1e-3) {
      ps.deformation_gradient[0] = ps.elastic_deformation_gradient[0];
      ps.plastic_deformation_gradient[0] = Mat3::Identity();
    }
  }
  EXPECT_GT(clamped_steps, 1000);  // the random steps drive it plastic most of the time
}

TEST(SvdPlasticity, HardeningRaisesAndSofteningLowersTheLameParametersUnderPlasticCompression) {
  // Uniform compression in steps of 1 %: F_E clamps at 1 − c, the rest goes to F_P, J_P falls.
  const Mat3 compression = -0.01 * Mat3::Identity();
  const Mat3 probe = 1e-3 * (Mat3() << 1, 2, 0, 0, -1, 1, 1, 0, 0.5).finished();
  const std::vector<double> zetas = {10.0, 0.0, -10.0};
  std::vector<SvdPlasticity> materials;
  std::vector<particles::ParticleSet> states(zetas.size());
  for (std::size_t k = 0; k < zetas.size(); ++k) {
    materials.emplace_back("m", parameters(zetas[k]));
    states[k].add(0, Vec3::Zero(), Vec3::Zero(), 1.0, 1.0, 0);
  }
  std::vector<double> previous_energy(zetas.size(), 0.0);
  double previous_jp = 1.0;
  for (int n = 0; n < 30; ++n) {
    std::vector<double> energy(zetas.size());
    for (std::size_t k = 0; k < zetas.size(); ++k) {
      materials[k].update_state(states[k], 0, compression, {0.01});
      PotentialDerivatives d;
      ASSERT_TRUE(materials[k].evaluate(states[k], 0, probe, {0.01}, 0, d));
      energy[k] = d.energy;
    }
    // The same prescribed motion gives the same F_E and F_P whatever ζ: ζ only scales μ and λ.
    const double jp = states[1].plastic_deformation_gradient[0].determinant();
    EXPECT_EQ(states[0].elastic_deformation_gradient[0], states[1].elastic_deformation_gradient[0]);
    if (n < 5) continue;  // elastic until the singular values reach 1 − c = 0.95
    EXPECT_LT(jp, previous_jp);  // plastic compression: 0 < J_P^{n+1} < J_P^n < 1
    // §4.5.1: μ, λ ∝ e^{ζ(1 − J_P)} — every term of ψ scales with them, so does the probe energy.
    for (std::size_t k = 0; k < zetas.size(); ++k)
      EXPECT_NEAR(energy[k] / energy[1], std::exp(zetas[k] * (1.0 - jp)), 1e-12 * energy[k] / energy[1]);
    if (n > 5) {
      EXPECT_GT(energy[0], previous_energy[0]);  // hardening (ζ > 0, §4.5.1)
      EXPECT_LT(energy[2], previous_energy[2]);  // softening (ζ < 0, §4.5.2)
      EXPECT_NEAR(energy[1], previous_energy[1], 1e-12 * energy[1]);  // ζ = 0: perfect plasticity
    }
    const auto hardened = materials[0].lame(states[0], 0), softened = materials[2].lame(states[2], 0);
    EXPECT_GT(hardened.mu, 100.0);
    EXPECT_GT(hardened.lambda, 200.0);
    EXPECT_LT(softened.mu, 100.0);
    EXPECT_LT(softened.lambda, 200.0);
    previous_energy = energy;
    previous_jp = jp;
  }
  EXPECT_LT(previous_jp, 0.6);
}

TEST(SvdPlasticity, NoPlasticFlowInsideTheClampRange) {
  const SvdPlasticity material("snow", parameters(10.0));
  particles::ParticleSet ps;
  ps.add(0, Vec3::Zero(), Vec3::Zero(), 1.0, 1.0, 0);
  const Mat3 A = Vec3(0.01, -0.02, 0.015).asDiagonal();
  material.update_state(ps, 0, A, {0.01});
  EXPECT_LT(ps.yield_function[0], 0.0);
  EXPECT_LT((ps.elastic_deformation_gradient[0] - (Mat3::Identity() + A)).norm(), 1e-15);
  EXPECT_LT((ps.plastic_deformation_gradient[0] - Mat3::Identity()).norm(), 1e-15);
}
