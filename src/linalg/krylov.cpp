#include "krylov.hpp"
#include "preconditioner.hpp"

#include <BelosSolverFactory.hpp>
#include <algorithm>
#include <chrono>

namespace viscompm::linalg {

namespace {
// An operator counting the products Belos asks of it: a solve that throws (a breakdown) leaves the
// manager's iteration count at the previous solve's, so the count of a failed solve is taken here.
class CountingOperator : public operator_type {
 public:
  explicit CountingOperator(Teuchos::RCP<const operator_type> A) : A_(std::move(A)) {}
  Teuchos::RCP<const map_type> getDomainMap() const override { return A_->getDomainMap(); }
  Teuchos::RCP<const map_type> getRangeMap() const override { return A_->getRangeMap(); }
  void apply(const multivector_type& X, multivector_type& Y, Teuchos::ETransp mode, scalar_type alpha,
             scalar_type beta) const override {
    ++products;
    A_->apply(X, Y, mode, alpha, beta);
  }
  mutable int products = 0;

 private:
  Teuchos::RCP<const operator_type> A_;
};
}  // namespace

KrylovSolver::KrylovSolver(const SolverConfiguration& config) : config_(config) {
  Belos::SolverFactory<scalar_type, multivector_type, operator_type> factory;
  solver_ = factory.create(config.impl().settings.krylov_solver, config.impl().krylov_parameters);
  const auto& given = *config.impl().krylov_parameters;
  default_tolerance_ = given.isParameter("Convergence Tolerance")
                           ? given.get<double>("Convergence Tolerance")
                           : solver_->getValidParameters()->get<double>("Convergence Tolerance");
  current_tolerance_ = default_tolerance_;
  default_max_iterations_ = given.isParameter("Maximum Iterations")
                                ? given.get<int>("Maximum Iterations")
                                : solver_->getValidParameters()->get<int>("Maximum Iterations");
  current_max_iterations_ = default_max_iterations_;
}

LinearSolveReport KrylovSolver::solve(const Teuchos::RCP<const operator_type>& A,
                                      const Teuchos::RCP<operator_type>& M, multivector_type& x,
                                      const multivector_type& b, double tolerance, int max_iterations) {
  LinearSolveReport report;
  report.preconditioner = config_.label();
  if (tolerance <= 0.0) tolerance = default_tolerance_;
  max_iterations = max_iterations <= 0 ? default_max_iterations_ : std::min(max_iterations, default_max_iterations_);
  if (tolerance != current_tolerance_ || max_iterations != current_max_iterations_) {
    auto params = Teuchos::rcp(new Teuchos::ParameterList);
    params->set("Convergence Tolerance", tolerance);
    params->set("Maximum Iterations", max_iterations);
    solver_->setParameters(params);
    current_tolerance_ = tolerance;
    current_max_iterations_ = max_iterations;
  }
  report.tolerance = tolerance;
  x.putScalar(0.0);
  const auto counted = Teuchos::rcp(new CountingOperator(A));
  auto problem = Teuchos::rcp(new Belos::LinearProblem<scalar_type, multivector_type, operator_type>(
      counted, Teuchos::rcpFromRef(x), Teuchos::rcpFromRef(b)));
  if (!M.is_null()) problem->setLeftPrec(M);
  problem->setProblem();
  solver_->setProblem(problem);
  counted->products = 0;  // the initial residual of setProblem is not an iteration
  const auto start = std::chrono::steady_clock::now();
  try {
    report.converged = solver_->solve() == Belos::Converged;
    report.iterations = solver_->getNumIters();
  } catch (const std::exception& e) {
    report.converged = false;  // breakdown (e.g. an indefinite operator)
    report.failure = e.what();
    // One product per CG iteration; the manager's own count is still the last solve's.
    report.iterations = counted->products;
  }
  report.solve_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  // The true residual, whatever the solver's own stopping rule measured.
  multivector_type r(b.getMap(), 1);
  A->apply(x, r);
  r.update(1.0, b, -1.0);
  Teuchos::Array<double> r_norm(1), b_norm(1);
  r.norm2(r_norm());
  b.norm2(b_norm());
  report.relative_residual = b_norm[0] > 0.0 ? r_norm[0] / b_norm[0] : r_norm[0];
  if (!std::isfinite(report.relative_residual)) report.converged = false;
  return report;
}

}  // namespace viscompm::linalg
