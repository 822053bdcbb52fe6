// The Chapter 5 energy (Appendix A) and its derivatives against central finite differences, in
// the variables y = (F̂, Ŝ, ε̂) and in the step variable A, at random feasible states.
#include <gtest/gtest.h>

#include "model_variants.hpp"
#include "test_helpers.hpp"
#include "viscompm/materials/oldroyd_b.hpp"

using namespace viscompm;
using namespace viscompm::materials;
using oldroyd_b::Mat27;
using oldroyd_b::Vec27;

namespace {
struct State {
  Mat3 F, S, eps;
};

State random_state() {
  State s;
  do {
    s.F = Mat3::Identity() + testkit::random_matrix(0.4);
  } while (s.F.determinant() < 0.3);
  s.S = testkit::random_spd(0.4);
  s.eps = testkit::random_matrix(2.0);
  return s;
}

Vec27 pack(const State& s) {
  Vec27 y;
  y << vec(s.F), vec(s.S), vec(s.eps);
  return y;
}
State unpack(const Vec27& y) {
  return {unvec(y.segment<9>(0)), unvec(y.segment<9>(9)), unvec(y.segment<9>(18))};
}

const oldroyd_b::Coefficients coefficients{360.0, 1400.0, 0.7, 1.3};
}  // namespace

TEST(OldroydBEnergy, VanishesWithZeroStressAtRest) {
  const Mat3 I = Mat3::Identity();
  EXPECT_NEAR(oldroyd_b::energy_density(coefficients, I, I, Mat3::Zero()), 0.0, 1e-12);
  EXPECT_LT(oldroyd_b::energy_gradient(coefficients, I, I, Mat3::Zero()).norm(), 1e-12);
}

TEST(OldroydBEnergy, GradientMatchesFiniteDifferences) {
  for (int trial = 0; trial < 50; ++trial) {
    const State s = random_state();
    const Vec27 y = pack(s);
    const Vec27 g = oldroyd_b::energy_gradient(coefficients, s.F, s.S, s.eps);
    const double h = 1e-6;
    for (int k = 0; k < 27; ++k) {
      Vec27 plus = y, minus = y;
      plus[k] += h;
      minus[k] -= h;
      const State a = unpack(plus), b = unpack(minus);
      const double fd = (oldroyd_b::energy_density(coefficients, a.F, a.S, a.eps) -
                         oldroyd_b::energy_density(coefficients, b.F, b.S, b.eps)) / (2 * h);
      EXPECT_NEAR(g[k], fd, 1e-6 * (1.0 + std::abs(fd))) << "trial " << trial << " entry " << k;
    }
  }
}

TEST(OldroydBEnergy, HessianMatchesFiniteDifferencesOfGradient) {
  for (int trial = 0; trial < 50; ++trial) {
    const State s = random_state();
    const Vec27 y = pack(s);
    const Mat27 H = oldroyd_b::energy_hessian(coefficients, s.F, s.S, s.eps);
    EXPECT_LT((H - H.transpose()).norm(), 1e-9 * H.norm());
    const double h = 1e-6;
    for (int k = 0; k < 27; ++k) {
      Vec27 plus = y, minus = y;
      plus[k] += h;
      minus[k] -= h;
      const State a = unpack(plus), b = unpack(minus);
      const Vec27 fd = (oldroyd_b::energy_gradient(coefficients, a.F, a.S, a.eps) -
                        oldroyd_b::energy_gradient(coefficients, b.F, b.S, b.eps)) / (2 * h);
      EXPECT_LT((H.col(k) - fd).norm(), 1e-6 * (1.0 + fd.norm())) << "trial " << trial << " column " << k;
    }
  }
}

TEST(OldroydBEnergy, ElasticStrainHasDeterminantJSquared) {
  // (5.5): det b^E = J², so the plastic flow is volume preserving (§5.4.4).
  for (int trial = 0; trial < 100; ++trial) {
    const State s = random_state();
    const Mat3 bE = oldroyd_b::elastic_left_cauchy_green(s.F, s.S);
    EXPECT_NEAR(bE.determinant(), s.F.determinant() * s.F.determinant(), 1e-12 * bE.determinant());
  }
}

class OldroydBMaterial : public ::testing::TestWithParam<std::string> {
 protected:
  OldroydB material() const {
    OldroydBParameters p = testkit::parsed_parameters<OldroydBParameters>({{"Viscosity convention", GetParam()}});
    p.density = 2.0;
    p.shear_modulus = 360.0;
    p.lame_lambda = 1400.0;
    p.newtonian_viscosity = 0.3;
    p.weissenberg = 0.8;
    return OldroydB("test", p);
  }
};

TEST_P(OldroydBMaterial, StepDerivativesMatchFiniteDifferences) {
  const OldroydB m = material();
  const StepContext step{0.01};
  for (int trial = 0; trial < 30; ++trial) {
    particles::ParticleSet ps;
    ps.add(0, Vec3::Zero(), Vec3::Zero(), 1.0, 0.37, 0);
    const State s = random_state();
    ps.deformation_gradient[0] = s.F;
    ps.left_cauchy_green_ob[0] = s.S;
    const Mat3 A = testkit::random_matrix(0.05);
    PotentialDerivatives d;
    ASSERT_TRUE(m.evaluate(ps, 0, A, step, 2, d));
    auto energy = [&](const Mat3& a) {
      PotentialDerivatives e;
      EXPECT_TRUE(m.evaluate(ps, 0, a, step, 0, e));
      return e.energy;
    };
    const Vec9 fd = testkit::finite_difference_gradient(energy, A, 1e-7);
    EXPECT_LT((vec(d.gradient) - fd).norm(), 1e-6 * (1.0 + fd.norm())) << "trial " << trial;
    for (int k = 0; k < 9; ++k) {
      Mat3 plus = A, minus = A;
      plus.data()[k] += 1e-7;
      minus.data()[k] -= 1e-7;
      PotentialDerivatives dp, dm;
      ASSERT_TRUE(m.evaluate(ps, 0, plus, step, 1, dp));
      ASSERT_TRUE(m.evaluate(ps, 0, minus, step, 1, dm));
      const Vec9 column = (vec(dp.gradient) - vec(dm.gradient)) / 2e-7;
      EXPECT_LT((d.hessian.col(k) - column).norm(), 1e-5 * (1.0 + column.norm())) << "trial " << trial;
    }
  }
}

TEST_P(OldroydBMaterial, RejectsInfeasibleStates) {
  const OldroydB m = material();
  particles::ParticleSet ps;
  ps.add(0, Vec3::Zero(), Vec3::Zero(), 1.0, 1.0, 0);
  PotentialDerivatives d;
  // I + A with negative determinant inverts the particle: infeasible (§5.7).
  EXPECT_FALSE(m.evaluate(ps, 0, Mat3(Vec3(-2.0, 0.0, 0.0).asDiagonal()), {0.01}, 0, d));
  EXPECT_TRUE(m.evaluate(ps, 0, Mat3::Zero(), {0.01}, 0, d));
}

TEST_P(OldroydBMaterial, UpdateStateUsesThePredictedStrains) {
  const OldroydB m = material();
  particles::ParticleSet ps;
  ps.add(0, Vec3::Zero(), Vec3::Zero(), 1.0, 1.0, 0);
  const State s = random_state();
  ps.deformation_gradient[0] = s.F;
  ps.left_cauchy_green_ob[0] = s.S;
  const Mat3 A = testkit::random_matrix(0.1);
  m.update_state(ps, 0, A, {0.02});
  EXPECT_LT((ps.deformation_gradient[0] - (Mat3::Identity() + A) * s.F).norm(), 1e-14);
  // (5.14): S + A S + S Aᵀ + (Δt/Wi)(I − S).
  const Mat3 expected = s.S + A * s.S + s.S * A.transpose() + 0.02 / 0.8 * (Mat3::Identity() - s.S);
  EXPECT_LT((ps.left_cauchy_green_ob[0] - expected).norm(), 1e-14);
}

INSTANTIATE_TEST_SUITE_P(Conventions, OldroydBMaterial, ::testing::Values("paper", "physical"));

TEST(ViscosityConvention, PaperAndPhysicalCoefficients) {
  OldroydBParameters p;
  p.newtonian_viscosity = 2.5;
  p.viscosity_convention = ViscosityConvention::paper;
  EXPECT_DOUBLE_EQ(OldroydB("a", p).viscous_coefficient(0.01), 2.5);  // Φ^N = μ^N ε̂:ε̂ V^n (5.11)
  p.viscosity_convention = ViscosityConvention::physical;
  EXPECT_DOUBLE_EQ(OldroydB("b", p).viscous_coefficient(0.01), 0.025);  // Φ^N = Δt η ε̂:ε̂ V^n
}
