// Neo-Hookean elasticity (§2.5.4 in the form of (5.8)): ψ(F), P = ∂ψ/∂F and ∂²ψ/∂F² against
// central differences at random states, and the analytic Cauchy stress of simple shear.
#include <gtest/gtest.h>

#include "test_helpers.hpp"
#include "viscompm/materials/neo_hookean.hpp"

using namespace viscompm;
using namespace viscompm::materials;

namespace {
const neo_hookean::Lame lame{3.6, 14.0};

Mat3 random_deformation() {
  Mat3 F;
  do F = Mat3::Identity() + testkit::random_matrix(0.4);
  while (F.determinant() < 0.3);
  return F;
}
}  // namespace

TEST(NeoHookeanEnergy, VanishesWithZeroStressAtRest) {
  EXPECT_NEAR(neo_hookean::energy_density(lame, Mat3::Identity()), 0.0, 1e-15);
  EXPECT_LT(neo_hookean::first_piola(lame, Mat3::Identity()).norm(), 1e-14);
}

TEST(NeoHookeanEnergy, StressAndHessianMatchFiniteDifferences) {
  for (int trial = 0; trial < 50; ++trial) {
    const Mat3 F = random_deformation();
    const Vec9 fd = testkit::finite_difference_gradient(
        [](const Mat3& G) { return neo_hookean::energy_density(lame, G); }, F, 1e-6);
    EXPECT_LT((vec(neo_hookean::first_piola(lame, F)) - fd).norm(), 1e-7 * (1.0 + fd.norm()));
    const Mat9 H = neo_hookean::energy_hessian(lame, F);
    for (int k = 0; k < 9; ++k) {
      Mat3 plus = F, minus = F;
      plus.data()[k] += 1e-6;
      minus.data()[k] -= 1e-6;
      const Vec9 column = vec(neo_hookean::first_piola(lame, plus) - neo_hookean::first_piola(lame, minus)) / 2e-6;
      EXPECT_LT((H.col(k) - column).norm(), 1e-7 * (1.0 + column.norm())) << "trial " << trial;
    }
    // τ = P Fᵀ, and symmetric (the balance of angular momentum, §2.5.1 condition 3).
    const Mat3 tau = neo_hookean::kirchhoff_stress(lame, F);
    EXPECT_LT((tau - neo_hookean::first_piola(lame, F) * F.transpose()).norm(), 1e-12 * (1.0 + tau.norm()));
    EXPECT_LT((tau - tau.transpose()).norm(), 1e-12 * (1.0 + tau.norm()));
  }
}

TEST(NeoHookeanEnergy, SimpleShearHasTheAnalyticCauchyStress) {
  // F = I + γ e_x e_yᵀ, J = 1: σ = μ (b − I), so σ_xy = μ γ, σ_xx − σ_yy = μ γ² (the first normal
  // stress difference of a Neo-Hookean solid), σ_yy = σ_zz = 0.
  for (double gamma : {0.1, 0.5, 2.0}) {
    Mat3 F = Mat3::Identity();
    F(0, 1) = gamma;
    const Mat3 sigma = neo_hookean::kirchhoff_stress(lame, F) / F.determinant();
    EXPECT_NEAR(sigma(0, 1), lame.mu * gamma, 1e-12);
    EXPECT_NEAR(sigma(0, 0) - sigma(1, 1), lame.mu * gamma * gamma, 1e-12);
    EXPECT_NEAR(sigma(1, 1), 0.0, 1e-12);
    EXPECT_NEAR(sigma(2, 2), 0.0, 1e-12);
  }
}
