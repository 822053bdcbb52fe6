// The L-BFGS memory: its two-loop recursion against the dense BFGS inverse-Hessian update it
// stands for, the curvature condition, the limited memory, and minimisation of a quadratic
// (exact after n steps with exact line searches, as BFGS).
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <random>

#include "viscompm/newton/lbfgs_memory.hpp"

using namespace viscompm;
using newton::LbfgsMemory;

namespace {
using Dense = Eigen::MatrixXd;
using DenseVector = Eigen::VectorXd;

NodeVectorField field(const DenseVector& x) {
  NodeVectorField f(x.size() / 3);
  for (std::size_t i = 0; i < f.size(); ++i) f[i] = x.segment<3>(3 * static_cast<Eigen::Index>(i));
  return f;
}
DenseVector dense(const NodeVectorField& f) {
  DenseVector x(3 * f.size());
  for (std::size_t i = 0; i < f.size(); ++i) x.segment<3>(3 * static_cast<Eigen::Index>(i)) = f[i];
  return x;
}
double dot(const NodeVectorField& a, const NodeVectorField& b) { return dense(a).dot(dense(b)); }

Dense random_spd(int n, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Dense a(n, n);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) a(i, j) = u(rng);
  return a * a.transpose() + n * Dense::Identity(n, n);
}
}  // namespace

TEST(LbfgsMemory, TheTwoLoopRecursionAppliesTheBfgsInverseUpdate) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const int n = 12;
  const Dense A = random_spd(n, rng), H0 = random_spd(n, rng).inverse();
  LbfgsMemory memory(3);
  Dense H = H0;  // dense BFGS of the pairs the memory holds (the last 3)
  std::vector<std::pair<DenseVector, DenseVector>> pairs;
  for (int k = 0; k < 5; ++k) {
    const DenseVector s = DenseVector::NullaryExpr(n, [&] { return u(rng); });
    const DenseVector y = A * s;  // curvature s·Ay > 0
    ASSERT_TRUE(memory.add(field(s), field(y), dot));
    pairs.emplace_back(s, y);
  }
  for (std::size_t k = pairs.size() - 3; k < pairs.size(); ++k) {
    const auto& [s, y] = pairs[k];
    const double rho = 1.0 / y.dot(s);
    const Dense V = Dense::Identity(n, n) - rho * y * s.transpose();
    H = V.transpose() * H * V + rho * s * s.transpose();
  }
  const DenseVector g = DenseVector::NullaryExpr(n, [&] { return u(rng); });
  NodeVectorField d;
  memory.direction(field(g), d, dot, [&](const NodeVectorField& r, NodeVectorField& z) { z = field(H0 * dense(r)); },
                   false);
  EXPECT_LT((dense(d) + H * g).norm(), 1e-10 * (H * g).norm());
}

TEST(LbfgsMemory, PairsWithoutPositiveCurvatureAreNotKept) {
  LbfgsMemory memory(8);
  const DenseVector s = DenseVector::Ones(6);
  EXPECT_FALSE(memory.add(field(s), field(-s), dot));
  EXPECT_FALSE(memory.add(field(s), field(DenseVector::Zero(6)), dot));
  EXPECT_EQ(memory.size(), 0);
  EXPECT_TRUE(memory.add(field(s), field(2.0 * s), dot));
  EXPECT_EQ(memory.size(), 1);
}

TEST(LbfgsMemory, MinimisesAQuadraticInNStepsWithExactLineSearches) {
  // With exact line searches on a quadratic, (L-)BFGS with memory ≥ n is conjugate gradients:
  // the minimum after at most n steps, from any SPD initial inverse.
  std::mt19937 rng(3);
  const int n = 9;
  const Dense A = random_spd(n, rng), H0 = random_spd(n, rng).inverse();
  const DenseVector b = DenseVector::LinSpaced(n, -1.0, 2.0);
  LbfgsMemory memory(n);
  DenseVector x = DenseVector::Zero(n);
  for (int k = 0; k < n; ++k) {
    const DenseVector g = A * x - b;
    NodeVectorField d;
    memory.direction(field(g), d, dot, [&](const NodeVectorField& r, NodeVectorField& z) { z = field(H0 * dense(r)); },
                     false);
    const DenseVector p = dense(d);
    ASSERT_LT(g.dot(p), 0.0) << "a descent direction at step " << k;
    const double alpha = -g.dot(p) / p.dot(A * p);
    const DenseVector s = alpha * p;
    x += s;
    memory.add(field(s), field(A * s), dot);
  }
  EXPECT_LT((A * x - b).norm(), 1e-9 * b.norm());
}
