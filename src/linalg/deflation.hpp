// Deflation of the stiff bodies' rigid motions (solver files: Deflation = stiff bodies). The
// coarse space Z — the 6 rigid-body modes of each stiff body on the nodes its cells reach
// (implicit/stiff_bodies) — is solved exactly and the preconditioner M handles the rest, in the
// balancing form (Mandel 1993; the "A-DEF2"/BNN preconditioner of Tang et al. 2009):
//   M_D⁻¹ = Q + (I − Q A) M⁻¹ (I − A Q),   Q = Z (Zᵀ A Z)⁺ Zᵀ,
// symmetric and positive definite whenever M is (also when A has changed since Q was built), so
// CG applies. A application of M_D costs M⁻¹ and four products with the n × k matrices Z and
// A Z (k = 6 per body), kept by rows with their nonzeros only (a body's modes live on its own
// nodes, A Z two nodes further), so that they cost what the bodies cover, not n × k. Z is a
// sparse matrix, so its set-up is one sparse product A Z (Tpetra's, where A is assembled; k
// products with A otherwise). Private to src/linalg.
#pragma once

#include <memory>
#include <vector>

#include "linalg_types.hpp"

namespace viscompm::linalg {

class DeflatedPreconditioner : public operator_type {
 public:
  /// M⁻¹ deflated by the k columns of Z (rows on A's domain map, k columns) for the operator A,
  /// whose assembled matrix `A_matrix` (null for a matrix-free A) gives A Z as a sparse product
  /// (collective).
  DeflatedPreconditioner(const operator_type& A, const Teuchos::RCP<const crs_matrix_type>& A_matrix,
                         Teuchos::RCP<operator_type> M, const crs_matrix_type& Z);

  Teuchos::RCP<const map_type> getDomainMap() const override { return map_; }
  Teuchos::RCP<const map_type> getRangeMap() const override { return map_; }
  void apply(const multivector_type& X, multivector_type& Y, Teuchos::ETransp mode = Teuchos::NO_TRANS,
             scalar_type alpha = Teuchos::ScalarTraits<scalar_type>::one(),
             scalar_type beta = Teuchos::ScalarTraits<scalar_type>::zero()) const override;
  /// Columns of Z kept after dropping those A cannot tell apart (rank of Zᵀ A Z).
  int rank() const { return rank_; }

 private:
  /// The nonzeros of an n × k matrix, row by row (compressed sparse rows; columns 0 … k−1).
  struct SparseRows {
    explicit SparseRows(const multivector_type& V);
    explicit SparseRows(const crs_matrix_type& V);
    std::vector<std::size_t> row_start;
    std::vector<int> column;
    std::vector<double> value;
  };
  /// c = E⁺ (Vᵀ x) for the k columns V (Z or A Z): a global product, then the small solve.
  std::vector<double> project(const SparseRows& V, const vector_type& x) const;
  /// y += s · V c.
  static void add_columns(const SparseRows& V, const std::vector<double>& c, double s, vector_type& y);

  Teuchos::RCP<operator_type> M_;
  Teuchos::RCP<const map_type> map_;
  std::unique_ptr<SparseRows> z_rows_, az_rows_;
  std::vector<double> pseudo_inverse_;  // E⁺, k × k, row-major
  int k_ = 0, rank_ = 0;
};

}  // namespace viscompm::linalg
