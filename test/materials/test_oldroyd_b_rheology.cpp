// The b_OB update (5.14) against the analytic Oldroyd-B solutions of DESIGN.md §3 under a
// prescribed velocity gradient: start-up of simple shear and relaxation after a step strain.
// The update is forward Euler in time, so the error must halve with Δt (first order).
#include <gtest/gtest.h>

#include <cmath>

#include "viscompm/materials/oldroyd_b.hpp"

using namespace viscompm;
using namespace viscompm::materials;

namespace {
constexpr double wi = 0.5, rate = 2.0, end_time = 1.0;

OldroydB material() {
  OldroydBParameters p;
  p.weissenberg = wi;
  return OldroydB("fluid", p);
}

// b_OB after end_time of shear v_x = γ̇ y starting from b = I, with steps of dt.
Mat3 integrate_startup_shear(double dt) {
  particles::ParticleSet ps;
  ps.add(0, Vec3::Zero(), Vec3::Zero(), 1.0, 1.0, 0);
  Mat3 L = Mat3::Zero();
  L(0, 1) = rate;
  const OldroydB m = material();
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
}  // namespace

TEST(OldroydBRheology, StartUpOfShearConvergesAtFirstOrder) {
  const Mat3 exact = analytic_startup_shear(end_time);
  std::vector<double> errors;
  for (double dt : {1e-2, 5e-3, 2.5e-3, 1.25e-3}) errors.push_back((integrate_startup_shear(dt) - exact).norm());
  for (std::size_t k = 1; k < errors.size(); ++k) {
    const double order = std::log2(errors[k - 1] / errors[k]);
    EXPECT_NEAR(order, 1.0, 0.1) << "errors " << errors[k - 1] << " -> " << errors[k];
  }
  EXPECT_LT(errors.back(), 1e-2 * exact.norm());
  // The structure of the solution: b_yy = 1 and b_zz = 1 exactly, shear stress positive.
  const Mat3 b = integrate_startup_shear(1.25e-3);
  EXPECT_NEAR(b(1, 1), 1.0, 1e-12);
  EXPECT_NEAR(b(2, 2), 1.0, 1e-12);
  EXPECT_GT(b(0, 1), 0.0);
}

TEST(OldroydBRheology, RelaxationAfterStepStrainDecaysAsExponential) {
  // After a step shear of amount γ, b − I decays as e^{−t/Wi} with no flow.
  const double gamma = 0.8;
  std::vector<double> errors;
  for (double dt : {1e-2, 5e-3, 2.5e-3}) {
    particles::ParticleSet ps;
    ps.add(0, Vec3::Zero(), Vec3::Zero(), 1.0, 1.0, 0);
    Mat3 b0 = Mat3::Identity();
    b0(0, 1) = b0(1, 0) = gamma;
    b0(0, 0) = 1.0 + gamma * gamma;
    ps.left_cauchy_green_ob[0] = b0;
    const OldroydB m = material();
    for (int n = 0; n < std::lround(end_time / dt); ++n) m.update_state(ps, 0, Mat3::Zero(), {dt});
    const Mat3 exact = Mat3::Identity() + (b0 - Mat3::Identity()) * std::exp(-end_time / wi);
    errors.push_back((ps.left_cauchy_green_ob[0] - exact).norm());
  }
  EXPECT_NEAR(std::log2(errors[0] / errors[1]), 1.0, 0.1);
  EXPECT_NEAR(std::log2(errors[1] / errors[2]), 1.0, 0.1);
}
