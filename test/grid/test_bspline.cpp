#include <gtest/gtest.h>

#include "test_helpers.hpp"
#include "viscompm/grid/bspline.hpp"

using namespace viscompm;
using grid::KernelOrder;

class BSpline : public ::testing::TestWithParam<KernelOrder> {};

TEST_P(BSpline, WeightsSumToOneAndGradientsToZeroAtRandomPoints) {
  const KernelOrder order = GetParam();
  const int width = grid::stencil_width(order);
  const Vec3 origin(-0.3, 0.1, 2.0);
  const double dx = 0.07;
  for (int trial = 0; trial < 1000; ++trial) {
    const Vec3 x = origin + Vec3(testkit::uniform(3, 20), testkit::uniform(3, 20), testkit::uniform(3, 20)) * dx;
    const grid::Stencil s = grid::make_stencil(order, origin, dx, x);
    double sum = 0.0;
    Vec3 grad_sum = Vec3::Zero();
    Vec3 first_moment = Vec3::Zero();
    for (int c = 0; c < width; ++c)
      for (int b = 0; b < width; ++b)
        for (int a = 0; a < width; ++a) {
          EXPECT_GE(s.w(a, b, c), 0.0);
          sum += s.w(a, b, c);
          grad_sum += s.grad_w(a, b, c);
          const Vec3 xi = origin + dx * (s.base + Int3(a, b, c)).cast<double>();
          first_moment += s.w(a, b, c) * (xi - x);
        }
    EXPECT_NEAR(sum, 1.0, 1e-13);
    EXPECT_LT(grad_sum.norm(), 1e-11);
    // B-splines also reproduce linear functions: Σ w_i (x_i − x) = 0.
    EXPECT_LT(first_moment.norm(), 1e-13);
  }
}

TEST_P(BSpline, DerivativeMatchesFiniteDifferences) {
  const KernelOrder order = GetParam();
  const double support = order == KernelOrder::quadratic ? 1.5 : 2.0;
  for (int trial = 0; trial < 1000; ++trial) {
    const double r = testkit::uniform(-support - 0.2, support + 0.2);
    const double h = 1e-6;
    const double fd = (grid::bspline_value(order, r + h) - grid::bspline_value(order, r - h)) / (2 * h);
    EXPECT_NEAR(grid::bspline_derivative(order, r), fd, 1e-6) << "r = " << r;
  }
}

TEST_P(BSpline, IsContinuousAtItsKnots) {
  const KernelOrder order = GetParam();
  const std::vector<double> knots = order == KernelOrder::quadratic ? std::vector<double>{0.5, 1.5}
                                                                    : std::vector<double>{1.0, 2.0};
  for (double k : knots) {
    EXPECT_NEAR(grid::bspline_value(order, k - 1e-12), grid::bspline_value(order, k + 1e-12), 1e-10);
    EXPECT_NEAR(grid::bspline_derivative(order, k - 1e-12), grid::bspline_derivative(order, k + 1e-12), 1e-10);
  }
}

TEST(BSplineCubic, MatchesThesisFormulaAtSamplePoints) {
  // N(0) = 2/3, N(1) = 1/6, N(2) = 0 for the cubic kernel of §3.1.
  EXPECT_NEAR(grid::bspline_value(KernelOrder::cubic, 0.0), 2.0 / 3.0, 1e-15);
  EXPECT_NEAR(grid::bspline_value(KernelOrder::cubic, 1.0), 1.0 / 6.0, 1e-15);
  EXPECT_NEAR(grid::bspline_value(KernelOrder::cubic, -1.0), 1.0 / 6.0, 1e-15);
  EXPECT_EQ(grid::bspline_value(KernelOrder::cubic, 2.0), 0.0);
  EXPECT_NEAR(grid::bspline_value(KernelOrder::quadratic, 0.0), 0.75, 1e-15);
}

INSTANTIATE_TEST_SUITE_P(Orders, BSpline, ::testing::Values(KernelOrder::quadratic, KernelOrder::cubic),
                         [](const auto& info) { return grid::kernel_name(info.param); });
