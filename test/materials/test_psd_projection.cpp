#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>

#include "test_helpers.hpp"
#include "viscompm/materials/psd_projection.hpp"

using namespace viscompm;

namespace {
Mat9 random_symmetric(const Vec9& eigenvalues) {
  Mat9 r;
  for (int i = 0; i < 81; ++i) r.data()[i] = testkit::uniform(-1, 1);
  const Eigen::HouseholderQR<Mat9> qr(r);
  const Mat9 Q = qr.householderQ();
  return Q * eigenvalues.asDiagonal() * Q.transpose();
}
}  // namespace

TEST(PsdProjection, RemovesNegativeEigenvaluesAndKeepsThePositivePart) {
  for (int trial = 0; trial < 200; ++trial) {
    Vec9 lambda;
    for (int k = 0; k < 9; ++k) lambda[k] = testkit::uniform(-5, 5);
    lambda[0] = -1.0;  // at least one negative
    Mat9 h = random_symmetric(lambda);
    const Mat9 original = h;
    EXPECT_TRUE(materials::project_to_psd(h));
    const Vec9 projected = Eigen::SelfAdjointEigenSolver<Mat9>(h).eigenvalues();
    EXPECT_GE(projected.minCoeff(), -1e-12 * lambda.cwiseAbs().maxCoeff());
    // The nearest PSD matrix: eigenvalues clamped at zero, eigenvectors kept.
    Vec9 expected = lambda.cwiseMax(0.0);
    std::sort(expected.data(), expected.data() + 9);
    EXPECT_LT((projected - expected).norm(), 1e-11);
    EXPECT_GT((h - original).norm(), 0.5);
  }
}

TEST(PsdProjection, LeavesPsdMatricesUnchanged) {
  for (int trial = 0; trial < 200; ++trial) {
    Vec9 lambda;
    for (int k = 0; k < 9; ++k) lambda[k] = testkit::uniform(0.0, 5.0);
    if (trial % 2) lambda[3] = 0.0;  // singular but PSD (rotation modes at rest)
    Mat9 h = random_symmetric(lambda);
    h = 0.5 * (h + h.transpose());
    const Mat9 original = h;
    EXPECT_FALSE(materials::project_to_psd(h));
    EXPECT_EQ(h, original);  // bit for bit
  }
}
