#include "lean_cycle.hpp"

#include <MueLu_Hierarchy.hpp>
#include <MueLu_Utilities.hpp>

namespace viscompm::linalg {

LeanCycle::LeanCycle(Teuchos::RCP<const operator_type> A, std::shared_ptr<const LineSmoother> smoother,
                     Teuchos::RCP<muelu_hierarchy_type> hierarchy)
    : A_(std::move(A)), smoother_(std::move(smoother)), hierarchy_(std::move(hierarchy)) {
  const auto level = hierarchy_->GetLevel(1);
  P_ = muelu_utilities_type::Op2TpetraCrs(level->template Get<Teuchos::RCP<xpetra_matrix_type>>("P"));
  R_ = muelu_utilities_type::Op2TpetraCrs(level->template Get<Teuchos::RCP<xpetra_matrix_type>>("R"));
}

void LeanCycle::apply(const multivector_type& X, multivector_type& Y, Teuchos::ETransp, scalar_type alpha,
                      scalar_type beta) const {
  const std::size_t k = X.getNumVectors();
  multivector_type x(A_->getDomainMap(), k), residual(A_->getRangeMap(), k), correction(A_->getDomainMap(), k);
  auto coarse_b = Teuchos::rcp(new multivector_type(R_->getRangeMap(), k));
  auto coarse_x = Teuchos::rcp(new multivector_type(P_->getDomainMap(), k));
  // Pre-smoothing from zero.
  smoother_->apply(X, x);
  // Coarse correction of the residual.
  A_->apply(x, residual);
  residual.update(1.0, X, -1.0);
  R_->apply(residual, *coarse_b);
  coarse_x->putScalar(0.0);
  hierarchy_->Iterate(*MueLu::TpetraMultiVector_To_XpetraMultiVector(coarse_b),
                      *MueLu::TpetraMultiVector_To_XpetraMultiVector(coarse_x), 1, true, 1);
  P_->apply(*coarse_x, x, Teuchos::NO_TRANS, 1.0, 1.0);
  // Post-smoothing.
  A_->apply(x, residual);
  residual.update(1.0, X, -1.0);
  smoother_->apply(residual, correction);
  x.update(1.0, correction, 1.0);
  Y.update(alpha, x, beta);
}

}  // namespace viscompm::linalg
