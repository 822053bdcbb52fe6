// The b updates of Chapters 4–5 over long sequences of large random velocity gradients:
// - §4.6.1 (oldroyd_b spd), §4.7.1 (oldroyd_b f_e) and §4.6.2 (herschel_bulkley) keep b symmetric
//   positive definite, where the paper's (5.14) loses definiteness;
// - the volume correction (5.5) gives det b^E = J² for every update (§5.4.4: J_P = 1).
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>

#include "model_variants.hpp"
#include "test_helpers.hpp"
#include "viscompm/materials/herschel_bulkley.hpp"
#include "viscompm/materials/oldroyd_b.hpp"

using namespace viscompm;
using namespace viscompm::materials;

namespace {
constexpr int steps = 5000;
constexpr double dt = 0.01;

std::unique_ptr<Material> make(const std::string& update) {
  if (update == "herschel_bulkley") {
    HerschelBulkleyParameters p;
    p.yield_stress = 0.1;
    p.plastic_viscosity = 0.02;
    p.flow_index = 0.7;
    return std::make_unique<HerschelBulkley>("hb", p);
  }
  OldroydBParameters p = testkit::parsed_parameters<OldroydBParameters>({{"Strain update", update}});
  p.weissenberg = 0.02;  // Δt/Wi = 0.5
  return std::make_unique<OldroydB>("ob", p);
}

// A large random velocity increment A = Δt ∇v: entries up to ±0.5, det(I + A) ≥ 0.05 (the line
// search rejects inverting steps, §5.7).
Mat3 random_large_increment() {
  Mat3 A;
  do A = testkit::random_matrix(0.5);
  while ((Mat3::Identity() + A).determinant() < 0.05);
  return A;
}

struct History {
  int first_indefinite_step = -1;  ///< -1: b stayed positive definite
  double worst_asymmetry = 0.0;    ///< max ‖b − bᵀ‖/‖b‖
  double worst_volume_error = 0.0; ///< max |det b^E / J² − 1|
};

History run(const Material& material) {
  particles::ParticleSet ps;
  ps.add(0, Vec3::Zero(), Vec3::Zero(), 1.0, 1.0, 0);
  History h;
  for (int n = 0; n < steps; ++n) {
    const Mat3 A = random_large_increment();
    material.update_state(ps, 0, A, {dt});
    const Mat3& b = ps.left_cauchy_green_ob[0];
    h.worst_asymmetry = std::max(h.worst_asymmetry, (b - b.transpose()).norm() / b.norm());
    const double lowest = Eigen::SelfAdjointEigenSolver<Mat3>(b).eigenvalues().minCoeff();
    if (h.first_indefinite_step < 0 && !(lowest > 0.0 && Eigen::LLT<Mat3>(b).info() == Eigen::Success))
      h.first_indefinite_step = n;
    if (h.first_indefinite_step >= 0) break;  // (5.14) beyond this point has no b^E
    const double J = ps.deformation_gradient[0].determinant();
    ps.deformation_gradient[0] /= std::cbrt(J);  // keep F bounded; b is independent of F
    const double J_now = ps.deformation_gradient[0].determinant();
    const Mat3 bE = material.left_cauchy_green_elastic(ps, 0);
    h.worst_volume_error = std::max(h.worst_volume_error, std::abs(bE.determinant() / (J_now * J_now) - 1.0));
  }
  return h;
}
}  // namespace

TEST(StrainUpdates, PaperUpdateLosesDefinitenessUnderLargeVelocityGradients) {
  // The reason §4.6 exists: (5.14) is b + Δt(L b + b Lᵀ) + ..., indefinite for large Δt L.
  const History h = run(*make("paper"));
  EXPECT_GE(h.first_indefinite_step, 0);
  EXPECT_LT(h.first_indefinite_step, 50);
}

class SpdUpdate : public ::testing::TestWithParam<std::string> {};

TEST_P(SpdUpdate, KeepsTheStrainSymmetricPositiveDefiniteForThousandsOfSteps) {
  const History h = run(*make(GetParam()));
  EXPECT_EQ(h.first_indefinite_step, -1);
  EXPECT_LT(h.worst_asymmetry, 1e-15);
  // (5.5) with J_OB = √det b: det b^E = J² at every step (§5.4.4).
  EXPECT_LT(h.worst_volume_error, 1e-11);
}

INSTANTIATE_TEST_SUITE_P(Updates, SpdUpdate, ::testing::Values("spd", "f_e", "herschel_bulkley"));

TEST(StrainUpdates, SpdUpdateSolvesTheImplicitRelaxationOfSection461) {
  // §4.6.1: (b^{n+1} − b^n)/Δt = L b^n + b^n Lᵀ + Δt L b^n Lᵀ + (I − b^{n+1})/Wi, at any Δt.
  const auto material = make("spd");
  particles::ParticleSet ps;
  ps.add(0, Vec3::Zero(), Vec3::Zero(), 1.0, 1.0, 0);
  const Mat3 b_n = testkit::random_spd(0.5);
  ps.left_cauchy_green_ob[0] = b_n;
  const double step = 0.3, wi = 0.02;
  const Mat3 L = testkit::random_matrix(2.0);
  material->update_state(ps, 0, step * L, {step});
  const Mat3& b = ps.left_cauchy_green_ob[0];
  const Mat3 residual = (b - b_n) / step - (L * b_n + b_n * L.transpose() + step * L * b_n * L.transpose() +
                                            (Mat3::Identity() - b) / wi);
  EXPECT_LT(residual.norm(), 1e-12 * b.norm() / wi);
}

TEST(StrainUpdates, FeRecastGivesTheOldroydBStrainAsFeFeTransposed) {
  // §4.7: f_e f_eᵀ obeys the Oldroyd-B equation, so one step of §4.7.1 and one of (5.14) agree to
  // O(Δt²): their difference over Δt² tends to a constant.
  std::vector<double> scaled_differences;
  for (double step : {1e-2, 5e-3, 2.5e-3, 1.25e-3}) {
    OldroydBParameters p;
    p.weissenberg = 0.5;
    p.strain_update = OldroydBUpdate::f_e;
    const OldroydB fe("fe", p);
    p.strain_update = OldroydBUpdate::paper;
    const OldroydB paper("paper", p);
    particles::ParticleSet a, b;
    a.add(0, Vec3::Zero(), Vec3::Zero(), 1.0, 1.0, 0);
    b.add(0, Vec3::Zero(), Vec3::Zero(), 1.0, 1.0, 0);
    const Mat3 f = Mat3::Identity() + 0.3 * Mat3::Ones().triangularView<Eigen::StrictlyUpper>().toDenseMatrix();
    a.elastic_deformation_gradient[0] = f;
    b.left_cauchy_green_ob[0] = f * f.transpose();
    Mat3 L = Mat3::Zero();
    L(0, 1) = 2.0;
    L(1, 0) = -0.5;
    fe.update_state(a, 0, step * L, {step});
    paper.update_state(b, 0, step * L, {step});
    const Mat3& f_new = a.elastic_deformation_gradient[0];
    EXPECT_LT((a.left_cauchy_green_ob[0] - f_new * f_new.transpose()).norm(), 1e-15);
    scaled_differences.push_back((a.left_cauchy_green_ob[0] - b.left_cauchy_green_ob[0]).norm() / (step * step));
  }
  EXPECT_GT(scaled_differences.back(), 0.1);  // not identical updates
  for (std::size_t k = 1; k < scaled_differences.size(); ++k)
    EXPECT_NEAR(scaled_differences[k] / scaled_differences[k - 1], 1.0, 0.05);
}
