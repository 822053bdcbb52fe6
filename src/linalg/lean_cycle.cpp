#include "lean_cycle.hpp"

#include <MueLu_Hierarchy.hpp>
#include <MueLu_Utilities.hpp>
#include <Teuchos_TimeMonitor.hpp>

namespace viscompm::linalg {

namespace {
// Where a cycle's time goes, printed with the programs' timers ("viscompm: lean cycle: ...").
Teuchos::Time& timer(const char* name) { return *Teuchos::TimeMonitor::getNewCounter(name); }
Teuchos::Time& smoother_timer() { static Teuchos::Time& t = timer("viscompm: lean cycle: 1 line smoother"); return t; }
Teuchos::Time& residual_timer() { static Teuchos::Time& t = timer("viscompm: lean cycle: 2 fine residuals"); return t; }
Teuchos::Time& transfer_timer() { static Teuchos::Time& t = timer("viscompm: lean cycle: 3 restrict, prolong"); return t; }
Teuchos::Time& coarse_timer() { static Teuchos::Time& t = timer("viscompm: lean cycle: 4 coarse levels"); return t; }
}  // namespace

LeanCycle::LeanCycle(Teuchos::RCP<const operator_type> A, std::shared_ptr<const LineSmoother> smoother,
                     Teuchos::RCP<muelu_hierarchy_type> hierarchy, int sweeps)
    : A_(std::move(A)), smoother_(std::move(smoother)), hierarchy_(std::move(hierarchy)), sweeps_(sweeps) {
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
  // residual = X − A x.
  const auto form_residual = [&] {
    Teuchos::TimeMonitor t(residual_timer());
    A_->apply(x, residual);
    residual.update(1.0, X, -1.0);
  };
  // One sweep of the smoother on x: x += S (X − A x).
  const auto sweep = [&] {
    form_residual();
    Teuchos::TimeMonitor t(smoother_timer());
    smoother_->apply(residual, correction);
    x.update(1.0, correction, 1.0);
  };
  // Pre-smoothing: the first sweep from zero (x = S X, no product), then the rest.
  {
    Teuchos::TimeMonitor t(smoother_timer());
    smoother_->apply(X, x);
  }
  for (int s = 1; s < sweeps_; ++s) sweep();
  // Coarse correction of the residual.
  form_residual();
  {
    Teuchos::TimeMonitor t(transfer_timer());
    R_->apply(residual, *coarse_b);
  }
  {
    Teuchos::TimeMonitor t(coarse_timer());
    coarse_x->putScalar(0.0);
    hierarchy_->Iterate(*MueLu::TpetraMultiVector_To_XpetraMultiVector(coarse_b),
                        *MueLu::TpetraMultiVector_To_XpetraMultiVector(coarse_x), 1, true, 1);
  }
  {
    Teuchos::TimeMonitor t(transfer_timer());
    P_->apply(*coarse_x, x, Teuchos::NO_TRANS, 1.0, 1.0);
  }
  // Post-smoothing: as many sweeps as before (the cycle stays symmetric).
  for (int s = 0; s < sweeps_; ++s) sweep();
  Y.update(alpha, x, beta);
}

}  // namespace viscompm::linalg
