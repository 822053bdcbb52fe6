#include "deflation.hpp"

#include <Eigen/Eigenvalues>
#include <TpetraExt_MatrixMatrix.hpp>
#include <Teuchos_CommHelpers.hpp>
#include <Teuchos_TimeMonitor.hpp>

namespace viscompm::linalg {

namespace {
// The deflation's own work per application (M excluded), printed with the programs' timers.
Teuchos::Time& deflation_timer() {
  static Teuchos::Time& t = *Teuchos::TimeMonitor::getNewCounter("viscompm: deflation: projections");
  return t;
}
}  // namespace

DeflatedPreconditioner::DeflatedPreconditioner(const operator_type& A, const Teuchos::RCP<const crs_matrix_type>& A_matrix,
                                               Teuchos::RCP<operator_type> M, const crs_matrix_type& Z)
    : M_(std::move(M)), map_(Z.getRowMap()), k_(static_cast<int>(Z.getGlobalNumCols())) {
  z_rows_ = std::make_unique<SparseRows>(Z);
  if (!A_matrix.is_null()) {
    // A Z: the sparse product (A's rows times the few mode values of the body nodes they reach).
    const auto AZ = Teuchos::rcp(new crs_matrix_type(A_matrix->getRowMap(), 0));
    Tpetra::MatrixMatrix::Multiply(*A_matrix, false, Z, false, *AZ);
    az_rows_ = std::make_unique<SparseRows>(*AZ);
  } else {
    multivector_type dense(map_, k_), AZ(map_, k_);
    {
      auto d = dense.getLocalViewHost(Tpetra::Access::OverwriteAll);
      for (std::size_t i = 0; i + 1 < z_rows_->row_start.size(); ++i) {
        for (int a = 0; a < k_; ++a) d(i, a) = 0.0;
        for (std::size_t e = z_rows_->row_start[i]; e < z_rows_->row_start[i + 1]; ++e)
          d(i, z_rows_->column[e]) = z_rows_->value[e];
      }
    }
    A.apply(dense, AZ);
    az_rows_ = std::make_unique<SparseRows>(AZ);
  }
  // E = Zᵀ A Z (every rank the same), and its pseudo-inverse: modes A cannot tell apart (a body
  // held by a sticky collider, two bodies' modes on the same nodes) are dropped.
  std::vector<double> local(static_cast<std::size_t>(k_) * k_, 0.0), E(local.size()), az(k_, 0.0);
  for (std::size_t i = 0; i + 1 < z_rows_->row_start.size(); ++i) {
    if (z_rows_->row_start[i] == z_rows_->row_start[i + 1]) continue;
    for (std::size_t e = az_rows_->row_start[i]; e < az_rows_->row_start[i + 1]; ++e) az[az_rows_->column[e]] = az_rows_->value[e];
    for (std::size_t e = z_rows_->row_start[i]; e < z_rows_->row_start[i + 1]; ++e)
      for (int b = 0; b < k_; ++b) local[z_rows_->column[e] * k_ + b] += z_rows_->value[e] * az[b];
    for (std::size_t e = az_rows_->row_start[i]; e < az_rows_->row_start[i + 1]; ++e) az[az_rows_->column[e]] = 0.0;
  }
  Teuchos::reduceAll(*map_->getComm(), Teuchos::REDUCE_SUM, k_ * k_, local.data(), E.data());
  Eigen::MatrixXd matrix = Eigen::Map<Eigen::MatrixXd>(E.data(), k_, k_);
  matrix = 0.5 * (matrix + matrix.transpose()).eval();
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(matrix);
  const double largest = k_ > 0 ? eigen.eigenvalues().cwiseAbs().maxCoeff() : 0.0;
  Eigen::VectorXd inverse = Eigen::VectorXd::Zero(k_);
  for (int a = 0; a < k_; ++a)
    if (eigen.eigenvalues()[a] > 1e-12 * largest) {
      inverse[a] = 1.0 / eigen.eigenvalues()[a];
      ++rank_;
    }
  const Eigen::MatrixXd E_plus = eigen.eigenvectors() * inverse.asDiagonal() * eigen.eigenvectors().transpose();
  pseudo_inverse_.resize(local.size());
  for (int a = 0; a < k_; ++a)
    for (int b = 0; b < k_; ++b) pseudo_inverse_[a * k_ + b] = E_plus(a, b);
}

DeflatedPreconditioner::SparseRows::SparseRows(const crs_matrix_type& V) {
  const std::size_t n = V.getNodeNumRows();
  const auto& columns = *V.getColMap();
  row_start.reserve(n + 1);
  row_start.push_back(0);
  for (std::size_t i = 0; i < n; ++i) {
    crs_matrix_type::local_inds_host_view_type cols;
    crs_matrix_type::values_host_view_type vals;
    V.getLocalRowView(static_cast<local_ordinal_type>(i), cols, vals);
    for (std::size_t e = 0; e < cols.extent(0); ++e)
      if (vals(e) != 0.0) {
        column.push_back(static_cast<int>(columns.getGlobalElement(cols(e))));
        value.push_back(vals(e));
      }
    row_start.push_back(column.size());
  }
}

DeflatedPreconditioner::SparseRows::SparseRows(const multivector_type& V) {
  auto v = V.getLocalViewHost(Tpetra::Access::ReadOnly);
  row_start.reserve(v.extent(0) + 1);
  row_start.push_back(0);
  for (std::size_t i = 0; i < v.extent(0); ++i) {
    for (std::size_t a = 0; a < v.extent(1); ++a)
      if (v(i, a) != 0.0) {
        column.push_back(static_cast<int>(a));
        value.push_back(v(i, a));
      }
    row_start.push_back(column.size());
  }
}

std::vector<double> DeflatedPreconditioner::project(const SparseRows& V, const vector_type& x) const {
  std::vector<double> local(k_, 0.0), product(k_);
  auto xv = x.getLocalViewHost(Tpetra::Access::ReadOnly);
  for (std::size_t i = 0; i + 1 < V.row_start.size(); ++i)
    for (std::size_t e = V.row_start[i]; e < V.row_start[i + 1]; ++e) local[V.column[e]] += V.value[e] * xv(i, 0);
  Teuchos::reduceAll(*map_->getComm(), Teuchos::REDUCE_SUM, k_, local.data(), product.data());
  std::vector<double> c(k_, 0.0);
  for (int a = 0; a < k_; ++a)
    for (int b = 0; b < k_; ++b) c[a] += pseudo_inverse_[a * k_ + b] * product[b];
  return c;
}

void DeflatedPreconditioner::add_columns(const SparseRows& V, const std::vector<double>& c, double s,
                                         vector_type& y) {
  auto yv = y.getLocalViewHost(Tpetra::Access::ReadWrite);
  for (std::size_t i = 0; i + 1 < V.row_start.size(); ++i) {
    double sum = 0.0;
    for (std::size_t e = V.row_start[i]; e < V.row_start[i + 1]; ++e) sum += V.value[e] * c[V.column[e]];
    yv(i, 0) += s * sum;
  }
}

void DeflatedPreconditioner::apply(const multivector_type& X, multivector_type& Y, Teuchos::ETransp, scalar_type alpha,
                                   scalar_type beta) const {
  for (std::size_t j = 0; j < X.getNumVectors(); ++j) {
    const auto x = X.getVector(j);
    // r' = (I − A Q) x, then z = M⁻¹ r' (or r' without M).
    std::vector<double> c;
    vector_type r(*x, Teuchos::Copy), z(map_);
    {
      Teuchos::TimeMonitor t(deflation_timer());
      c = project(*z_rows_, *x);
      add_columns(*az_rows_, c, -1.0, r);
    }
    if (M_.is_null()) z.assign(r);
    else M_->apply(r, z);
    // (I − Q A) z + Q x.
    {
      Teuchos::TimeMonitor t(deflation_timer());
      const std::vector<double> d = project(*az_rows_, z);
      add_columns(*z_rows_, d, -1.0, z);
      add_columns(*z_rows_, c, 1.0, z);
    }
    auto y = Y.getVectorNonConst(j);
    y->update(alpha, z, beta);
  }
}

}  // namespace viscompm::linalg
