// The grid gradient and Hessian of the incremental potential E(v) against finite differences of
// E on a small grid (before PSD projection), for both kernels.
#include <gtest/gtest.h>

#include <Eigen/Dense>

#include "test_helpers.hpp"
#include "viscompm/implicit/incremental_potential.hpp"
#include "viscompm/materials/oldroyd_b.hpp"
#include "viscompm/transfer/transfer.hpp"

using namespace viscompm;

namespace {
struct Problem {
  grid::GridGeometry geometry;
  particles::ParticleSet particles;
  grid::GridLayout layout;
  materials::MaterialList materials;
  NodeScalarField mass;
  NodeVectorField v_star;
  boundary::NodeConstraints constraints;
  double dt = 2e-3;

  Problem(grid::KernelOrder order, double strain) {
    geometry.dx = 0.1;
    geometry.cells = Int3(8, 8, 8);
    materials::OldroydBParameters p;
    p.shear_modulus = 50.0;
    p.lame_lambda = 200.0;
    p.newtonian_viscosity = 0.05;
    p.weissenberg = 0.3;
    materials.push_back(std::make_unique<materials::OldroydB>("m", p));
    // Particles in a few cells, with random (feasible) stored strains.
    for (int k = 0; k < 20; ++k) {
      const Vec3 x = Vec3(testkit::uniform(3.2, 4.8), testkit::uniform(3.2, 4.8), testkit::uniform(3.2, 4.8)) * geometry.dx;
      particles.add(k, x, Vec3::Zero(), testkit::uniform(0.5, 1.5) * 1e-3, 1e-3, 0);
      Mat3 F;
      do {
        F = Mat3::Identity() + testkit::random_matrix(strain);
      } while (F.determinant() < 0.4);
      particles.deformation_gradient.back() = F;
      particles.left_cauchy_green_ob.back() = testkit::random_spd(strain);
    }
    layout = testkit::serial_layout(particles, geometry, order);
    NodeVectorField momentum;
    transfer::particles_to_grid(particles, layout, transfer::Scheme::pic_flip, mass, momentum);
    v_star.resize(mass.size());
    for (auto& v : v_star) v = Vec3(testkit::uniform(-1, 1), testkit::uniform(-1, 1), testkit::uniform(-1, 1));
    constraints.projection.assign(mass.size(), Mat3::Identity());
    constraints.prescribed.assign(mass.size(), Vec3::Zero());
  }

  implicit::IncrementalPotential potential() const {
    return implicit::IncrementalPotential(particles, layout, materials, mass, v_star, constraints, dt);
  }

  Eigen::MatrixXd dense_hessian(const implicit::IncrementalPotential& E, const NodeVectorField& v,
                                bool project = false) const {
    const int n = static_cast<int>(3 * layout.local_node_count());
    Eigen::MatrixXd H = Eigen::MatrixXd::Zero(n, n);
    const int K = layout.nodes_per_cell();
    E.element_hessians(v, project, [&](std::size_t c, const implicit::ElementHessian& element) {
      const int* nodes = layout.nodes_of_cell(c);
      for (int a = 0; a < K; ++a)
        for (int b = a; b < K; ++b) {
          const Mat3 B = E.constrained_block(element, c, a, b);
          H.block<3, 3>(3 * nodes[a], 3 * nodes[b]) += B;
          if (b != a) H.block<3, 3>(3 * nodes[b], 3 * nodes[a]) += B.transpose();
        }
    });
    for (std::size_t i = 0; i < mass.size(); ++i) H.block<3, 3>(3 * i, 3 * i) += mass[i] * Mat3::Identity();
    return H;
  }
};

NodeVectorField random_velocity(std::size_t n, double scale) {
  NodeVectorField v(n);
  for (auto& x : v) x = scale * Vec3(testkit::uniform(-1, 1), testkit::uniform(-1, 1), testkit::uniform(-1, 1));
  return v;
}
}  // namespace

class IncrementalPotentialTest : public ::testing::TestWithParam<grid::KernelOrder> {};

TEST_P(IncrementalPotentialTest, GradientMatchesFiniteDifferencesOfEnergy) {
  const Problem problem(GetParam(), 0.2);
  const auto E = problem.potential();
  const NodeVectorField v = random_velocity(problem.mass.size(), 0.5);
  NodeVectorField g;
  ASSERT_TRUE(E.gradient(v, g));
  const double h = 1e-6;
  double worst = 0.0, scale = 0.0;
  for (std::size_t i = 0; i < v.size(); ++i)
    for (int d = 0; d < 3; ++d) {
      NodeVectorField plus = v, minus = v;
      plus[i][d] += h;
      minus[i][d] -= h;
      const double fd = (E.energy(plus).value - E.energy(minus).value) / (2 * h);
      worst = std::max(worst, std::abs(fd - g[i][d]));
      scale = std::max(scale, std::abs(fd));
    }
  EXPECT_LT(worst, 1e-6 * scale);
}

TEST_P(IncrementalPotentialTest, AssembledHessianMatchesFiniteDifferencesOfGradient) {
  const Problem problem(GetParam(), 0.2);
  const auto E = problem.potential();
  const NodeVectorField v = random_velocity(problem.mass.size(), 0.5);
  const Eigen::MatrixXd H = problem.dense_hessian(E, v);
  EXPECT_LT((H - H.transpose()).norm(), 1e-12 * H.norm());
  const double h = 1e-6;
  Eigen::MatrixXd fd(H.rows(), H.cols());
  for (std::size_t i = 0; i < v.size(); ++i)
    for (int d = 0; d < 3; ++d) {
      NodeVectorField plus = v, minus = v, g_plus, g_minus;
      plus[i][d] += h;
      minus[i][d] -= h;
      ASSERT_TRUE(E.gradient(plus, g_plus));
      ASSERT_TRUE(E.gradient(minus, g_minus));
      for (std::size_t j = 0; j < v.size(); ++j) fd.block<3, 1>(3 * j, 3 * i + d) = (g_plus[j] - g_minus[j]) / (2 * h);
    }
  EXPECT_LT((H - fd).norm(), 1e-6 * H.norm());
}

TEST_P(IncrementalPotentialTest, ProjectionChangesNothingWhereNotNeededAndMakesTheHessianPsd) {
  // At rest every particle Hessian is PSD (zero only along rotations): projection is the identity.
  const Problem at_rest(GetParam(), 0.0);
  const NodeVectorField zero(at_rest.mass.size(), Vec3::Zero());
  for (const Mat9& h : at_rest.potential().particle_hessians(zero, false))
    EXPECT_GT(Eigen::SelfAdjointEigenSolver<Mat9>(h).eigenvalues().minCoeff(), -1e-10 * h.norm());
  const Eigen::MatrixXd exact = at_rest.dense_hessian(at_rest.potential(), zero, false);
  const Eigen::MatrixXd projected = at_rest.dense_hessian(at_rest.potential(), zero, true);
  EXPECT_EQ((exact - projected).norm(), 0.0);
  // Strained and moving, particle Hessians are indefinite; the projected assembly is not.
  const Problem strained(GetParam(), 0.6);
  NodeVectorField large;
  do {
    large = random_velocity(strained.mass.size(), 3.0);
  } while (!strained.potential().energy(large).feasible());
  int indefinite = 0;
  for (const Mat9& h : strained.potential().particle_hessians(large, false))
    indefinite += Eigen::SelfAdjointEigenSolver<Mat9>(h).eigenvalues().minCoeff() < 0.0;
  EXPECT_GT(indefinite, 0);
  const Eigen::MatrixXd H = strained.dense_hessian(strained.potential(), large, true);
  const double min_eigenvalue = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(H).eigenvalues().minCoeff();
  EXPECT_GT(min_eigenvalue, 0.0);  // M + PSD: positive definite
}

TEST_P(IncrementalPotentialTest, ConstrainedComponentsHaveZeroGradientAndDecoupledRows) {
  Problem problem(GetParam(), 0.2);
  problem.constraints.projection[0] = Mat3::Zero();  // sticky node
  const Vec3 n = Vec3(1, 2, 2).normalized();
  problem.constraints.projection[1] = Mat3::Identity() - n * n.transpose();  // slip node
  const auto E = problem.potential();
  const NodeVectorField v = random_velocity(problem.mass.size(), 0.5);
  NodeVectorField g;
  ASSERT_TRUE(E.gradient(v, g));
  EXPECT_EQ(g[0].norm(), 0.0);
  EXPECT_LT(std::abs(g[1].dot(n)), 1e-14 * (1.0 + g[1].norm()));
  const Eigen::MatrixXd H = problem.dense_hessian(E, v);
  // The sticky rows hold only the mass diagonal.
  Eigen::MatrixXd rows = H.topRows(3);
  rows.block<3, 3>(0, 0) -= problem.mass[0] * Mat3::Identity();
  EXPECT_LT(rows.norm(), 1e-14 * H.norm());
}

INSTANTIATE_TEST_SUITE_P(Orders, IncrementalPotentialTest,
                         ::testing::Values(grid::KernelOrder::quadratic, grid::KernelOrder::cubic),
                         [](const auto& info) { return grid::kernel_name(info.param); });
