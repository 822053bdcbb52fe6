#include "viscompm/materials/psd_projection.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

namespace viscompm::materials {

bool project_to_psd(Mat9& h) {
  const Mat9 symmetric = 0.5 * (h + h.transpose());
  // Fast path: a pivoted LDLᵀ with no negative pivot (beyond rounding) certifies PSD.
  const double scale = symmetric.diagonal().cwiseAbs().maxCoeff();
  const Eigen::LDLT<Mat9> ldlt(symmetric);
  if (ldlt.info() == Eigen::Success && ldlt.vectorD().minCoeff() >= -1e-12 * scale) return false;
  Eigen::SelfAdjointEigenSolver<Mat9> eig(symmetric);
  const Vec9& lambda = eig.eigenvalues();
  // Eigenvalues within rounding of zero (e.g. rotations at rest) are not negative curvature.
  if (lambda.minCoeff() >= -1e-12 * lambda.cwiseAbs().maxCoeff()) return false;
  h = eig.eigenvectors() * lambda.cwiseMax(0.0).asDiagonal() * eig.eigenvectors().transpose();
  return true;
}

}  // namespace viscompm::materials
