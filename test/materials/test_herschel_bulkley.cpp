// The Herschel–Bulkley-like fluid (§4.2.4–4.2.5, update §4.6.2) as a rheometer would see it, with
// the strain update driven by a prescribed velocity gradient:
// - below the yield stress nothing flows plastically (a held strain keeps its stress);
// - above it, a held strain relaxes until the stress is back on the yield surface, and stops;
// - in steady simple shear the stress follows τ = τ_Y + K γ̇^h (Herschel & Bulkley): exponent h,
//   shear thinning for h < 1, Bingham for h = 1, thickening for h > 1.
// In the small-strain limit the flow rule gives ‖dev b̂‖ = σ_Y + η (‖D‖)^h with ‖D‖ = γ̇/√2 in
// simple shear, and the shear stress τ_xy = μ b^E_xy ≈ μ ‖dev b̂‖/√2.
#include <gtest/gtest.h>

#include <cmath>

#include "test_helpers.hpp"
#include "viscompm/materials/herschel_bulkley.hpp"
#include "viscompm/materials/registry.hpp"

using namespace viscompm;
using namespace viscompm::materials;

namespace {
HerschelBulkleyParameters parameters(double h, double yield_stress = 0.02, double eta = 0.01) {
  HerschelBulkleyParameters p;
  p.shear_modulus = 10.0;
  p.lame_lambda = 100.0;
  p.yield_stress = yield_stress;
  p.plastic_viscosity = eta;
  p.flow_index = h;
  return p;
}

Mat3 shear_increment(double amount) {
  Mat3 A = Mat3::Zero();
  A(0, 1) = amount;
  return A;
}

double deviatoric_norm(const Mat3& b) {
  const Mat3 b_hat = herschel_bulkley::unimodular(b);
  return (b_hat - b_hat.trace() / 3.0 * Mat3::Identity()).norm();
}

// The steady shear stress τ_xy/μ = b^E_xy (J = 1) at shear rate γ̇.
double steady_shear_stress(const HerschelBulkley& material, double rate) {
  particles::ParticleSet ps;
  ps.add(0, Vec3::Zero(), Vec3::Zero(), 1.0, 1.0, 0);
  const double dt = 1e-4 / rate;  // a strain of 1e-4 per step
  double previous = 0.0;
  for (int n = 1; n <= 30000; ++n) {
    material.update_state(ps, 0, shear_increment(rate * dt), {dt});
    if (n == 20000) previous = material.left_cauchy_green_elastic(ps, 0)(0, 1);
  }
  const double stress = material.left_cauchy_green_elastic(ps, 0)(0, 1);
  EXPECT_NEAR(stress, previous, 1e-6 * stress) << "not steady at rate " << rate;
  return stress;
}
}  // namespace

TEST(HerschelBulkley, NoPlasticFlowBelowTheYieldStress) {
  const HerschelBulkley material("foam", parameters(0.7, 0.2));
  particles::ParticleSet ps;
  ps.add(0, Vec3::Zero(), Vec3::Zero(), 1.0, 1.0, 0);
  material.update_state(ps, 0, shear_increment(0.1), {0.01});  // step strain: ‖dev b̂‖ ≈ 0.14 < 0.2
  const Mat3 held = ps.left_cauchy_green_ob[0];
  ASSERT_LT(deviatoric_norm(held), 0.2);
  for (int n = 0; n < 1000; ++n) material.update_state(ps, 0, Mat3::Zero(), {0.01});
  EXPECT_LT((ps.left_cauchy_green_ob[0] - held).norm(), 1e-13);
  EXPECT_LT(ps.yield_function[0], 0.0);
  EXPECT_EQ(ps.equivalent_plastic_strain[0], 0.0);
}

TEST(HerschelBulkley, AboveTheYieldStressAHeldStrainRelaxesToTheYieldSurface) {
  // With no flow, the excess e = ‖dev b̂‖ − σ_Y decays as de/dt = −c (e/η)^{1/h}, c = (2/3) tr b̂ ≈ 2:
  // exponentially for h = 1, in finite time for h > 1, and for h = 1/2 as e(t) ≈ η²/(c t): a creep
  // that never quite stops (§4.2.5).
  const double yield = 0.2, eta = 0.05, dt = 1e-3, duration = 20.0;
  for (double h : {0.5, 1.0, 2.0}) {
    const HerschelBulkley material("foam", parameters(h, yield, eta));
    particles::ParticleSet ps;
    ps.add(0, Vec3::Zero(), Vec3::Zero(), 1.0, 1.0, 0);
    material.update_state(ps, 0, shear_increment(0.6), {dt});  // ‖dev b̂‖ ≈ 0.85 > σ_Y
    double x = deviatoric_norm(ps.left_cauchy_green_ob[0]), x_before_last_second = 0.0;
    ASSERT_GT(x, 0.5);
    const int steps = static_cast<int>(duration / dt);
    for (int n = 0; n < steps; ++n) {
      if (n == steps - 1000) x_before_last_second = x;
      material.update_state(ps, 0, Mat3::Zero(), {dt});
      const double next = deviatoric_norm(ps.left_cauchy_green_ob[0]);
      ASSERT_LE(next, x + 1e-14) << "h " << h << " step " << n;  // relaxes monotonically
      x = next;
    }
    EXPECT_GT(ps.equivalent_plastic_strain[0], 0.0);
    if (h < 1.0) {
      // Still creeping, at the analytic distance η²/(c t) from the yield surface.
      EXPECT_GT(x, yield);
      EXPECT_NEAR(x - yield, eta * eta / (2.0 * duration), 0.1 * eta * eta / (2.0 * duration));
    } else {
      // On the yield surface, and stopped there. The rate is evaluated at time n (§4.6.2), so the
      // last plastic step may overshoot the surface by at most 2Δt (e/η)^{1/h} with e below the
      // point where that exceeds e: 4Δt²/η for h = 2 (nothing for h = 1, as 2Δt < η).
      const double overshoot = h > 1.0 ? 4.0 * dt * dt / eta : 1e-12;
      EXPECT_NEAR(x, yield, overshoot) << "h " << h;
      EXPECT_NEAR(x, x_before_last_second, 1e-13) << "h " << h;
      EXPECT_LE(ps.yield_function[0], overshoot);
    }
  }
}

TEST(HerschelBulkley, SteadyShearFollowsTheHerschelBulkleyLawWithExponentH) {
  const double mu_ratio_yield = 0.02, eta = 0.01;
  for (double h : {0.5, 1.0, 2.0}) {
    const HerschelBulkley material("fluid", parameters(h, mu_ratio_yield, eta));
    // Rates with a plastic excess η (γ̇/√2)^h between 0.002 and 0.03: small elastic strains.
    const double lo = std::sqrt(2.0) * std::pow(0.002 / eta, 1.0 / h), hi = std::sqrt(2.0) * std::pow(0.03 / eta, 1.0 / h);
    std::vector<double> rates, excess;
    for (int k = 0; k < 4; ++k) rates.push_back(lo * std::pow(hi / lo, k / 3.0));
    for (double rate : rates) {
      const double tau = steady_shear_stress(material, rate);
      const double predicted = (mu_ratio_yield + eta * std::pow(rate / std::sqrt(2.0), h)) / std::sqrt(2.0);
      EXPECT_NEAR(tau, predicted, 0.01 * predicted) << "h " << h << " rate " << rate;
      excess.push_back(tau - mu_ratio_yield / std::sqrt(2.0));
    }
    // The exponent of the excess stress in the rate is h (a log-log fit through the ends) ...
    const double exponent = std::log(excess.back() / excess.front()) / std::log(rates.back() / rates.front());
    EXPECT_NEAR(exponent, h, 0.03 * h) << "h " << h;
    // ... so the plastic viscosity (τ − τ_Y)/γ̇ falls with the rate for h < 1, is constant for
    // Bingham, and grows for h > 1 (§4.2.5.2–4.2.5.3).
    for (std::size_t k = 1; k < rates.size(); ++k) {
      const double ratio = (excess[k] / rates[k]) / (excess[k - 1] / rates[k - 1]);
      if (h < 1.0) EXPECT_LT(ratio, 0.9);
      if (h == 1.0) EXPECT_NEAR(ratio, 1.0, 0.02);
      if (h > 1.0) EXPECT_GT(ratio, 1.1);
    }
  }
}

TEST(HerschelBulkley, BinghamIsTheFlowIndexOneCase) {
  // The registry's bingham and herschel_bulkley with h = 1 are the same material.
  ParameterValues values;
  for (const auto& spec : find_model("bingham")->parameters) values.set(spec.name, spec.default_value);
  values.set("Yield stress", 0.05);
  values.set("Plastic viscosity", 0.3);
  const auto bingham = find_model("bingham")->create("b", values);
  values.set("Flow index", 1.0);
  const auto hb = find_model("herschel_bulkley")->create("h", values);
  EXPECT_EQ(bingham->model(), "bingham");
  particles::ParticleSet a, b;
  a.add(0, Vec3::Zero(), Vec3::Zero(), 1.0, 1.0, 0);
  b.add(0, Vec3::Zero(), Vec3::Zero(), 1.0, 1.0, 0);
  for (int n = 0; n < 200; ++n) {
    const Mat3 A = testkit::random_matrix(0.05);
    bingham->update_state(a, 0, A, {0.01});
    hb->update_state(b, 0, A, {0.01});
  }
  EXPECT_EQ(a.left_cauchy_green_ob[0], b.left_cauchy_green_ob[0]);
  EXPECT_GT(a.equivalent_plastic_strain[0], 0.0);
}
