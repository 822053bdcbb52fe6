// Every model of the registry, in every variant: the energy's gradient and Hessian in the step
// variable A (what the Newton solve uses) against central finite differences at random feasible
// states, and the interface's contracts (zero energy and stress at rest, infeasible states).
#include <gtest/gtest.h>

#include <set>

#include "model_variants.hpp"
#include "test_helpers.hpp"
#include "viscompm/materials/registry.hpp"

using namespace viscompm;
using namespace viscompm::materials;

namespace {
using Variant = testkit::ModelVariant;
std::vector<Variant> variants() { return testkit::model_variants(); }

void PrintTo(const Variant& v, std::ostream* os) { *os << v.label; }

std::unique_ptr<Material> build(const Variant& v) { return testkit::build_material(v, "test"); }

Mat3 random_deformation(double spread) {
  Mat3 F;
  do F = Mat3::Identity() + testkit::random_matrix(spread);
  while (F.determinant() < 0.3);
  return F;
}

// One particle with a random state in every field a model may read.
particles::ParticleSet random_particle() {
  particles::ParticleSet ps;
  ps.add(0, Vec3::Zero(), Vec3::Zero(), 1.0, 0.37, 0);
  ps.deformation_gradient[0] = random_deformation(0.4);
  ps.left_cauchy_green_ob[0] = testkit::random_spd(0.4);
  ps.elastic_deformation_gradient[0] = random_deformation(0.3);
  ps.plastic_deformation_gradient[0] = ps.elastic_deformation_gradient[0].inverse() * ps.deformation_gradient[0];
  ps.equivalent_plastic_strain[0] = testkit::uniform(0.0, 0.5);
  return ps;
}

class MaterialDerivatives : public ::testing::TestWithParam<Variant> {};
}  // namespace

TEST(MaterialRegistry, EveryModelIsCoveredByTheDerivativeChecks) {
  std::set<std::string> covered;
  for (const auto& v : variants()) covered.insert(v.model);
  for (const auto& name : model_names()) EXPECT_TRUE(covered.count(name)) << name << " has no derivative check";
}

TEST_P(MaterialDerivatives, GradientAndHessianMatchFiniteDifferences) {
  const auto material = build(GetParam());
  const StepContext step{0.01};
  int checked = 0;
  for (int trial = 0; trial < 40; ++trial) {
    particles::ParticleSet ps = random_particle();
    const Mat3 A = testkit::random_matrix(0.05);
    PotentialDerivatives d;
    if (!material->evaluate(ps, 0, A, step, 2, d)) continue;
    ++checked;
    auto energy = [&](const Mat3& a) {
      PotentialDerivatives e;
      EXPECT_TRUE(material->evaluate(ps, 0, a, step, 0, e));
      return e.energy;
    };
    // order 0 and 1 give the same energy and gradient as order 2.
    PotentialDerivatives d0, d1;
    ASSERT_TRUE(material->evaluate(ps, 0, A, step, 0, d0));
    ASSERT_TRUE(material->evaluate(ps, 0, A, step, 1, d1));
    EXPECT_EQ(d0.energy, d.energy);
    EXPECT_EQ(d1.gradient, d.gradient);

    const double h = 1e-6;
    const Vec9 fd = testkit::finite_difference_gradient(energy, A, h);
    EXPECT_LT((vec(d.gradient) - fd).norm(), 1e-6 * (1.0 + fd.norm())) << "trial " << trial;
    EXPECT_LT((d.hessian - d.hessian.transpose()).norm(), 1e-10 * (1.0 + d.hessian.norm()));
    for (int k = 0; k < 9; ++k) {
      Mat3 plus = A, minus = A;
      plus.data()[k] += h;
      minus.data()[k] -= h;
      PotentialDerivatives dp, dm;
      ASSERT_TRUE(material->evaluate(ps, 0, plus, step, 1, dp));
      ASSERT_TRUE(material->evaluate(ps, 0, minus, step, 1, dm));
      const Vec9 column = (vec(dp.gradient) - vec(dm.gradient)) / (2.0 * h);
      EXPECT_LT((d.hessian.col(k) - column).norm(), 1e-6 * (1.0 + column.norm()))
          << "trial " << trial << " column " << k;
    }
  }
  EXPECT_GE(checked, 30) << "too few feasible random states";
}

TEST_P(MaterialDerivatives, NoEnergyAndNoStressAtRest) {
  // A particle fresh from sampling (identity strains) under A = 0: Φ = 0, ∂Φ/∂A = 0 (Ψ(I) = 0,
  // the constant of (5.8)), whatever its model.
  const auto material = build(GetParam());
  particles::ParticleSet ps;
  ps.add(0, Vec3::Zero(), Vec3::Zero(), 1.0, 0.5, 0);
  PotentialDerivatives d;
  ASSERT_TRUE(material->evaluate(ps, 0, Mat3::Zero(), {0.01}, 2, d));
  EXPECT_NEAR(d.energy, 0.0, 1e-13);
  EXPECT_LT(d.gradient.norm(), 1e-12);
  // Rest is a minimum: the Hessian there is positive semi-definite.
  EXPECT_GE(Eigen::SelfAdjointEigenSolver<Mat9>(d.hessian).eigenvalues().minCoeff(), -1e-10 * d.hessian.norm());
}

TEST_P(MaterialDerivatives, InvertingStepsAreInfeasible) {
  // I + A with a negative determinant inverts the particle: the line search must see +∞ (§5.7).
  const auto material = build(GetParam());
  particles::ParticleSet ps;
  ps.add(0, Vec3::Zero(), Vec3::Zero(), 1.0, 1.0, 0);
  PotentialDerivatives d;
  EXPECT_FALSE(material->evaluate(ps, 0, Mat3(Vec3(-2.0, 0.0, 0.0).asDiagonal()), {0.01}, 0, d));
}

TEST_P(MaterialDerivatives, UpdateStoresTheStrainsTheEnergyWasMinimisedOver) {
  // Inside every yield surface (a small A from rest), update_state must store exactly the strains
  // evaluate predicted: the energy of the updated particle at A = 0 equals the energy evaluate gave
  // at A. Viscosity is switched off and Δt is tiny so that neither the viscous potential nor the
  // next step's relaxation (Δt/Wi, the plastic rate) enters the comparison.
  Variant v = GetParam();
  for (auto& [name, value] : v.values)
    if (name == "Newtonian viscosity") value = 0.0;
  const auto material = build(v);
  const StepContext step{1e-9};
  particles::ParticleSet ps;
  ps.add(0, Vec3::Zero(), Vec3::Zero(), 1.0, 1.0, 0);
  const Mat3 A = testkit::random_matrix(0.01);
  PotentialDerivatives predicted, stored;
  ASSERT_TRUE(material->evaluate(ps, 0, A, step, 0, predicted));
  material->update_state(ps, 0, A, step);
  ASSERT_TRUE(material->evaluate(ps, 0, Mat3::Zero(), step, 0, stored));
  EXPECT_GT(predicted.energy, 1e-6);
  EXPECT_NEAR(stored.energy, predicted.energy, 1e-7 * predicted.energy);
  EXPECT_LT((ps.deformation_gradient[0] - (Mat3::Identity() + A)).norm(), 1e-15);  // (5.12)
  EXPECT_LE(ps.yield_function[0], 0.0);
  for (const auto& field : material->state_fields()) {
    bool known = false;
    ps.for_each_field([&](const char* name, const auto&) { known |= field == name; });
    EXPECT_TRUE(known) << v.model << " lists unknown field " << field;
  }
}

INSTANTIATE_TEST_SUITE_P(AllModels, MaterialDerivatives, ::testing::ValuesIn(variants()),
                         [](const ::testing::TestParamInfo<Variant>& info) {
                           std::string name = info.param.label;
                           for (char& c : name)
                             if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
                           return name;
                         });
