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
// The same with (5.11) on dev ε̂ only ("Viscous strain" deviatoric).
const oldroyd_b::Coefficients deviatoric_coefficients{360.0, 1400.0, 0.7, 1.3, ViscousStrain::deviatoric};
}  // namespace

TEST(OldroydBEnergy, VanishesWithZeroStressAtRest) {
  const Mat3 I = Mat3::Identity();
  EXPECT_NEAR(oldroyd_b::energy_density(coefficients, I, I, Mat3::Zero()), 0.0, 1e-12);
  EXPECT_LT(oldroyd_b::energy_gradient(coefficients, I, I, Mat3::Zero()).norm(), 1e-12);
}

TEST(OldroydBEnergy, GradientMatchesFiniteDifferences) {
  for (const oldroyd_b::Coefficients& c : {coefficients, deviatoric_coefficients}) {
    for (int trial = 0; trial < 50; ++trial) {
      const State s = random_state();
      const Vec27 y = pack(s);
      const Vec27 g = oldroyd_b::energy_gradient(c, s.F, s.S, s.eps);
      const double h = 1e-6;
      for (int k = 0; k < 27; ++k) {
        Vec27 plus = y, minus = y;
        plus[k] += h;
        minus[k] -= h;
        const State a = unpack(plus), b = unpack(minus);
        const double fd = (oldroyd_b::energy_density(c, a.F, a.S, a.eps) -
                           oldroyd_b::energy_density(c, b.F, b.S, b.eps)) / (2 * h);
        EXPECT_NEAR(g[k], fd, 1e-6 * (1.0 + std::abs(fd))) << "trial " << trial << " entry " << k;
      }
    }
  }
}

TEST(OldroydBEnergy, HessianMatchesFiniteDifferencesOfGradient) {
  for (const oldroyd_b::Coefficients& c : {coefficients, deviatoric_coefficients}) {
    for (int trial = 0; trial < 50; ++trial) {
      const State s = random_state();
      const Vec27 y = pack(s);
      const Mat27 H = oldroyd_b::energy_hessian(c, s.F, s.S, s.eps);
      EXPECT_LT((H - H.transpose()).norm(), 1e-9 * H.norm());
      const double h = 1e-6;
      for (int k = 0; k < 27; ++k) {
        Vec27 plus = y, minus = y;
        plus[k] += h;
        minus[k] -= h;
        const State a = unpack(plus), b = unpack(minus);
        const Vec27 fd = (oldroyd_b::energy_gradient(c, a.F, a.S, a.eps) -
                          oldroyd_b::energy_gradient(c, b.F, b.S, b.eps)) / (2 * h);
        EXPECT_LT((H.col(k) - fd).norm(), 1e-6 * (1.0 + fd.norm())) << "trial " << trial << " column " << k;
      }
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

namespace {
// Table 5.2's toothpaste (ρ 1, μ 0.839, λ 8.39, μ^N 0.1 in the paper convention) as `model`
// (oldroyd_b or herschel_bulkley), with (5.11) on `viscous_strain` and μ^N = `viscosity`.
std::unique_ptr<Material> paste(const std::string& model, const std::string& viscous_strain, double viscosity = 0.1) {
  std::vector<std::pair<std::string, ParameterValue>> values = {
      {"Density", 1.0},
      {"Shear modulus", 0.839},
      {"Lame lambda", 8.39},
      {"Newtonian viscosity", viscosity},
      {"Viscosity convention", std::string("paper")},
      {"Viscous strain", viscous_strain}};
  if (model == "oldroyd_b") values.push_back({"Weissenberg number", 0.4});
  return testkit::build_material({model + "_" + viscous_strain, model, values}, "paste");
}

// A particle at rest in shape (b = I) but compressed to J^n = 0.8, as the paste in the falling rope.
particles::ParticleSet compressed_particle() {
  particles::ParticleSet ps;
  ps.add(0, Vec3::Zero(), Vec3::Zero(), 1.0, 1.0, 0);
  ps.deformation_gradient[0] = std::cbrt(0.8) * Mat3::Identity();
  return ps;
}

// One quasi-static step under a purely volumetric A = αI and no load: the α where ∂Φ/∂A : I = 0
// (Φ is convex in α here), by Newton on α.
double unloaded_alpha(const Material& m, const particles::ParticleSet& ps, double dt) {
  const Vec9 iota = vec(Mat3::Identity());
  double alpha = 0.0;
  for (int k = 0; k < 100; ++k) {
    PotentialDerivatives d;
    EXPECT_TRUE(m.evaluate(ps, 0, alpha * Mat3::Identity(), {dt}, 2, d));
    const double g = vec(d.gradient).dot(iota), h = iota.dot(d.hessian * iota);
    const double step = -g / h;
    alpha += step;
    if (std::abs(step) < 1e-14) break;
  }
  return alpha;
}
}  // namespace

class ViscousStrainOption : public ::testing::TestWithParam<std::string> {};

TEST_P(ViscousStrainOption, DeviatoricLeavesAVolumeChangeToTheElasticResponse) {
  // Asked by the crushed toothpaste (doc/scenes.md): (5.11) on the full ε̂ resists a change of
  // volume with a bulk viscosity 2c_N/3 (η = μ^N/Δt = 25 Pa s at Δt = 0.004, against a bulk
  // modulus of 9 Pa); on dev ε̂ it does not, and the volume is the elastic energy's alone.
  const std::string model = GetParam();
  const auto full = paste(model, "full"), deviatoric = paste(model, "deviatoric"), inviscid = paste(model, "full", 0.0);
  const particles::ParticleSet ps = compressed_particle();
  const double dt = 0.004, J_n = 0.8;

  // A pure volume rate: deviatoric is the inviscid energy; full adds c_N J^n (3 α²/Δt²) V^0.
  const Mat3 volumetric = 0.01 * Mat3::Identity();
  PotentialDerivatives f, d, e;
  ASSERT_TRUE(full->evaluate(ps, 0, volumetric, {dt}, 2, f));
  ASSERT_TRUE(deviatoric->evaluate(ps, 0, volumetric, {dt}, 2, d));
  ASSERT_TRUE(inviscid->evaluate(ps, 0, volumetric, {dt}, 2, e));
  EXPECT_NEAR(d.energy, e.energy, 1e-12 * std::abs(e.energy));
  EXPECT_LT((d.gradient - e.gradient).norm(), 1e-12 * e.gradient.norm());
  EXPECT_NEAR(f.energy - e.energy, 0.1 * J_n * 3.0 * std::pow(0.01 / dt, 2), 1e-9 * f.energy);
  // A pure shear (traceless, symmetric): the two options are the same potential; their Hessians
  // differ only along the volume rate: by 2 c_N J^n V^0 / (3 Δt²) vec(I) vec(I)ᵀ.
  Mat3 shear = Mat3::Zero();
  shear(0, 1) = shear(1, 0) = 0.01;
  ASSERT_TRUE(full->evaluate(ps, 0, shear, {dt}, 2, f));
  ASSERT_TRUE(deviatoric->evaluate(ps, 0, shear, {dt}, 2, d));
  EXPECT_NEAR(d.energy, f.energy, 1e-12 * f.energy);
  EXPECT_LT((d.gradient - f.gradient).norm(), 1e-12 * f.gradient.norm());
  const Vec9 iota = vec(Mat3::Identity());
  const Mat9 volume_rate = 2.0 * 0.1 * J_n / (3.0 * dt * dt) * iota * iota.transpose();
  EXPECT_LT((f.hessian - d.hessian - volume_rate).norm(), 1e-9 * f.hessian.norm());

  // One unloaded step from J^n = 0.8: deviatoric springs back to the elastic rest volume J = 1 in
  // one step, exactly as the inviscid paste; full keeps the particle crushed (J < 0.81).
  const double a_full = unloaded_alpha(*full, ps, dt), a_dev = unloaded_alpha(*deviatoric, ps, dt),
               a_inviscid = unloaded_alpha(*inviscid, ps, dt);
  const auto J_after = [&](double a) { return std::pow(1.0 + a, 3) * J_n; };
  EXPECT_NEAR(J_after(a_dev), 1.0, 1e-10);
  EXPECT_NEAR(a_dev, a_inviscid, 1e-12);
  EXPECT_GT(J_after(a_full), J_n);
  EXPECT_LT(J_after(a_full), 0.81);

  // The flow step (the b update after the solve) never changes the volume in either option: the
  // elastic strain's det b^E is J² of the stored F (5.5), whatever b_OB or b_HB became.
  for (const auto* m : {full.get(), deviatoric.get()}) {
    for (double a : {a_full, a_dev}) {
      particles::ParticleSet stepped = compressed_particle();
      m->update_state(stepped, 0, a * Mat3::Identity(), {dt});
      const double J = stepped.deformation_gradient[0].determinant();
      EXPECT_NEAR(J, J_after(a), 1e-12);
      EXPECT_NEAR(m->left_cauchy_green_elastic(stepped, 0).determinant(), J * J, 1e-12);
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Models, ViscousStrainOption, ::testing::Values("oldroyd_b", "herschel_bulkley"));

TEST(ViscousStrainOption, DefaultIsTheThesisAndTheChoicesAreFullAndDeviatoric) {
  // (A value outside the choices fails on read: test_scene, EveryModelValidatesItsParameters...)
  EXPECT_EQ(OldroydBParameters{}.viscous_strain, ViscousStrain::full);
  EXPECT_EQ(testkit::parsed_parameters<OldroydBParameters>({}).viscous_strain, ViscousStrain::full);
  const auto deviatoric =
      testkit::parsed_parameters<OldroydBParameters>({{"Viscous strain", std::string("deviatoric")}});
  EXPECT_EQ(deviatoric.viscous_strain, ViscousStrain::deviatoric);
  for (const auto& spec : OldroydBParameters::table().specs())
    if (spec.name == "Viscous strain") EXPECT_EQ(spec.choices, (std::vector<std::string>{"full", "deviatoric"}));
}
