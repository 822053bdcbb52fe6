// The staged, lane-vectorised element kernel against the dense product Σ_p D_p H_p D_pᵀ, with
// D_p(3i+σ, σ+3β) = ∇w_ip[β], for the quadratic (27 nodes), cubic (64) and any other stencil size.
#include <gtest/gtest.h>

#include <Eigen/Dense>

#include "test_helpers.hpp"
#include "viscompm/implicit/element_hessian.hpp"

using namespace viscompm;

class ElementHessianTest : public ::testing::TestWithParam<int> {};

TEST_P(ElementHessianTest, EqualsTheDenseSumOfParticleBlocks) {
  const int K = GetParam();
  implicit::ElementHessian element(K);
  Eigen::MatrixXd dense = Eigen::MatrixXd::Zero(3 * K, 3 * K);
  for (int round = 0; round < 2; ++round) {  // clear() must forget the first round
    element.clear();
    dense.setZero();
    for (int p = 0; p < 5; ++p) {
      Mat9 h;
      for (int k = 0; k < 81; ++k) h.data()[k] = testkit::uniform(-1, 1);
      h = (h + h.transpose()).eval();
      std::vector<Vec3> dw(K);
      Eigen::MatrixXd D = Eigen::MatrixXd::Zero(3 * K, 9);
      for (int i = 0; i < K; ++i) {
        dw[i] = Vec3(testkit::uniform(-2, 2), testkit::uniform(-2, 2), testkit::uniform(-2, 2));
        for (int sigma = 0; sigma < 3; ++sigma)
          for (int beta = 0; beta < 3; ++beta) D(3 * i + sigma, sigma + 3 * beta) = dw[i][beta];
      }
      element.add_particle(h, dw.data());
      dense += D * h * D.transpose();
    }
  }
  double worst = 0.0;
  for (int i = 0; i < K; ++i)
    for (int j = i; j < K; ++j) worst = std::max(worst, (element.block(i, j) - dense.block<3, 3>(3 * i, 3 * j)).norm());
  EXPECT_LT(worst, 1e-12 * dense.norm());
}

INSTANTIATE_TEST_SUITE_P(StencilSizes, ElementHessianTest, ::testing::Values(27, 64, 8));
