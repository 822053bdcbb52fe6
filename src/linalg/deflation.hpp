// Deflation of the stiff bodies' rigid motions (solver files: Deflation = stiff bodies). The
// coarse space Z — the 6 rigid-body modes of each stiff body on the nodes its cells reach
// (implicit/stiff_bodies) — is solved exactly and the preconditioner M handles the rest, in the
// balancing form (Mandel 1993; the "A-DEF2"/BNN preconditioner of Tang et al. 2009):
//   M_D⁻¹ = Q + (I − Q A) M⁻¹ (I − A Q),   Q = Z (Zᵀ A Z)⁺ Zᵀ,
// symmetric and positive definite whenever M is (also when A has changed since Q was built), so
// CG applies. A application of M_D costs M⁻¹ and four products with the n × k matrices Z and
// A Z (k = 6 per body), kept by rows with their nonzeros only (a body's modes live on its own
// nodes, A Z two nodes further), so that they cost what the bodies cover, not n × k; its set-up,
// the k products A Z. Private to src/linalg.
#pragma once

#include <memory>
#include <vector>

#include "linalg_types.hpp"

namespace viscompm::linalg {

class DeflatedPreconditioner : public operator_type {
 public:
  /// M⁻¹ deflated by the columns of Z (on A's domain map) for the operator A (collective).
  DeflatedPreconditioner(const operator_type& A, Teuchos::RCP<operator_type> M, Teuchos::RCP<const multivector_type> Z);

  Teuchos::RCP<const map_type> getDomainMap() const override { return Z_->getMap(); }
  Teuchos::RCP<const map_type> getRangeMap() const override { return Z_->getMap(); }
  void apply(const multivector_type& X, multivector_type& Y, Teuchos::ETransp mode = Teuchos::NO_TRANS,
             scalar_type alpha = Teuchos::ScalarTraits<scalar_type>::one(),
             scalar_type beta = Teuchos::ScalarTraits<scalar_type>::zero()) const override;
  /// Columns of Z kept after dropping those A cannot tell apart (rank of Zᵀ A Z).
  int rank() const { return rank_; }

 private:
  /// The nonzeros of an n × k multivector, row by row (compressed sparse rows).
  struct SparseRows {
    explicit SparseRows(const multivector_type& V);
    std::vector<std::size_t> row_start;
    std::vector<int> column;
    std::vector<double> value;
  };
  /// c = E⁺ (Vᵀ x) for the k columns V (Z or A Z): a global product, then the small solve.
  std::vector<double> project(const SparseRows& V, const vector_type& x) const;
  /// y += s · V c.
  static void add_columns(const SparseRows& V, const std::vector<double>& c, double s, vector_type& y);

  Teuchos::RCP<operator_type> M_;
  Teuchos::RCP<const multivector_type> Z_;
  std::unique_ptr<SparseRows> z_rows_, az_rows_;
  std::vector<double> pseudo_inverse_;  // E⁺, k × k, row-major
  int k_ = 0, rank_ = 0;
};

}  // namespace viscompm::linalg
