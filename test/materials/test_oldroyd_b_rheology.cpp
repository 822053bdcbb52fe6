// The b_OB updates — (5.14), the positive-definite §4.6.1 and the f_e recast §4.7.1 — against the
// analytic Oldroyd-B solutions of doc/numerics.md under a prescribed velocity gradient: start-up of
// simple shear and relaxation after a step strain. Each update is first order in time, so the
// error must halve with Δt.
#include <gtest/gtest.h>

#include <cmath>

#include "model_variants.hpp"
#include "viscompm/materials/oldroyd_b.hpp"

using namespace viscompm;
using namespace viscompm::materials;

namespace {
constexpr double wi = 0.5, rate = 2.0, end_time = 1.0;

OldroydB material(const std::string& update) {
  OldroydBParameters p = testkit::parsed_parameters<OldroydBParameters>({{"Strain update", update}});
  p.weissenberg = wi;
  return OldroydB("fluid", p);
}

// b_OB after end_time of shear v_x = γ̇ y starting from b = I, with steps of dt.
Mat3 integrate_startup_shear(const std::string& update, double dt) {
  particles::ParticleSet ps;
  ps.add(0, Vec3::Zero(), Vec3::Zero(), 1.0, 1.0, 0);
  Mat3 L = Mat3::Zero();
  L(0, 1) = rate;
  const OldroydB m = material(update);
  const int steps = static_cast<int>(std::lround(end_time / dt));
  for (int n = 0; n < steps; ++n) m.update_state(ps, 0, dt * L, {dt});
  return ps.left_cauchy_green_ob[0];
}

Mat3 analytic_startup_shear(double t) {
  const double decay = std::exp(-t / wi);
  Mat3 b = Mat3::Identity();
  b(0, 1) = b(1, 0) = rate * wi * (1.0 - decay);
  b(0, 0) = 1.0 + 2.0 * rate * rate * wi * wi * (1.0 - decay) - 2.0 * rate * rate * wi * t * decay;
  return b;
}

class OldroydBRheology : public ::testing::TestWithParam<std::string> {};
}  // namespace

TEST_P(OldroydBRheology, StartUpOfShearConvergesAtFirstOrder) {
  const Mat3 exact = analytic_startup_shear(end_time);
  std::vector<double> errors;
  for (double dt : {1e-2, 5e-3, 2.5e-3, 1.25e-3})
    errors.push_back((integrate_startup_shear(GetParam(), dt) - exact).norm());
  for (std::size_t k = 1; k < errors.size(); ++k) {
    const double order = std::log2(errors[k - 1] / errors[k]);
    EXPECT_NEAR(order, 1.0, 0.1) << "errors " << errors[k - 1] << " -> " << errors[k];
  }
  EXPECT_LT(errors.back(), 1e-2 * exact.norm());
  // The structure of the solution: b_yy = 1 and b_zz = 1, shear stress positive. The b updates
  // keep b_yy = b_zz = 1 exactly (their yy and zz rows decouple from the shear); f_e does only to
  // within its O(Δt) error (f_e^{-T} couples the components of f_e).
  const Mat3 b = integrate_startup_shear(GetParam(), 1.25e-3);
  const double structure_tolerance = GetParam() == "f_e" ? errors.back() : 1e-12;
  EXPECT_NEAR(b(1, 1), 1.0, structure_tolerance);
  EXPECT_NEAR(b(2, 2), 1.0, structure_tolerance);
  EXPECT_GT(b(0, 1), 0.0);
}

TEST_P(OldroydBRheology, RelaxationAfterStepStrainDecaysAsExponential) {
  // After a step shear of amount γ, b − I decays as e^{−t/Wi} with no flow.
  const double gamma = 0.8;
  std::vector<double> errors;
  for (double dt : {1e-2, 5e-3, 2.5e-3}) {
    particles::ParticleSet ps;
    ps.add(0, Vec3::Zero(), Vec3::Zero(), 1.0, 1.0, 0);
    Mat3 shear = Mat3::Identity();
    shear(0, 1) = gamma;
    const Mat3 b0 = shear * shear.transpose();  // b after the step shear x += γ y
    ps.left_cauchy_green_ob[0] = b0;
    ps.elastic_deformation_gradient[0] = shear;  // f_e with f_e f_eᵀ = b0 (§4.7)
    const OldroydB m = material(GetParam());
    for (int n = 0; n < std::lround(end_time / dt); ++n) m.update_state(ps, 0, Mat3::Zero(), {dt});
    const Mat3 exact = Mat3::Identity() + (b0 - Mat3::Identity()) * std::exp(-end_time / wi);
    errors.push_back((ps.left_cauchy_green_ob[0] - exact).norm());
  }
  EXPECT_NEAR(std::log2(errors[0] / errors[1]), 1.0, 0.1);
  EXPECT_NEAR(std::log2(errors[1] / errors[2]), 1.0, 0.1);
}

INSTANTIATE_TEST_SUITE_P(Updates, OldroydBRheology, ::testing::Values("paper", "spd", "f_e"));
