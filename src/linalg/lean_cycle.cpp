#include "lean_cycle.hpp"

#include <MueLu_Hierarchy.hpp>
#include <MueLu_Utilities.hpp>
#include <Teuchos_TimeMonitor.hpp>

#include <optional>

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
                     Teuchos::RCP<muelu_hierarchy_type> hierarchy, const FineSmoothing& smoothing)
    : A_(std::move(A)), smoother_(std::move(smoother)), hierarchy_(std::move(hierarchy)), smoothing_(smoothing) {
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
  // Chebyshev steps x += p(B A) B (X − A x) (Saad, Alg. 12.1), from x = 0 when `from_zero`; their
  // search direction is allocated only for them (the sweeps' cycle stays as it was).
  std::optional<multivector_type> chebyshev_direction;
  if (smoothing_.chebyshev) chebyshev_direction.emplace(A_->getDomainMap(), k);
  const auto chebyshev = [&](bool from_zero) {
    multivector_type& direction = *chebyshev_direction;
    const double upper = smoothing_.boost * smoother_->largest_eigenvalue(), lower = upper / smoothing_.ratio;
    const double theta = 0.5 * (upper + lower), delta = 0.5 * (upper - lower), sigma = theta / delta;
    double rho = 1.0 / sigma;
    if (from_zero) {
      Teuchos::TimeMonitor t(smoother_timer());
      smoother_->apply_undamped(X, direction);
    } else {
      form_residual();
      Teuchos::TimeMonitor t(smoother_timer());
      smoother_->apply_undamped(residual, direction);
    }
    direction.scale(1.0 / theta);
    if (from_zero) x.assign(direction);
    else x.update(1.0, direction, 1.0);
    for (int step = 1; step < smoothing_.steps; ++step) {
      const double rho_next = 1.0 / (2.0 * sigma - rho);
      form_residual();
      Teuchos::TimeMonitor t(smoother_timer());
      smoother_->apply_undamped(residual, correction);
      direction.update(2.0 * rho_next / delta, correction, rho_next * rho);
      x.update(1.0, direction, 1.0);
      rho = rho_next;
    }
  };
  // Pre-smoothing: the first sweep from zero (x = S X, no product), then the rest.
  if (smoothing_.chebyshev) {
    chebyshev(true);
  } else {
    {
      Teuchos::TimeMonitor t(smoother_timer());
      smoother_->apply(X, x);
    }
    for (int s = 1; s < smoothing_.steps; ++s) sweep();
  }
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
  // Post-smoothing: as many steps as before (the cycle stays symmetric).
  if (smoothing_.chebyshev) chebyshev(false);
  else
    for (int s = 0; s < smoothing_.steps; ++s) sweep();
  Y.update(alpha, x, beta);
}

}  // namespace viscompm::linalg
