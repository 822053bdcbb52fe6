#include "viscompm/newton/newton_solver.hpp"

#include <Teuchos_TimeMonitor.hpp>
#include <chrono>
#include <cmath>
#include <iomanip>
#include <limits>
#include <sstream>

namespace viscompm::newton {

namespace {
// The Newton phases' timers (doc/architecture.md), all here.
Teuchos::Time& timer(const char* name) { return *Teuchos::TimeMonitor::getNewCounter(name); }
Teuchos::Time& assemble_timer() { static auto& t = timer("viscompm: 3a newton assemble"); return t; }
Teuchos::Time& precondition_timer() { static auto& t = timer("viscompm: 3b newton precondition"); return t; }
Teuchos::Time& cg_timer() { static auto& t = timer("viscompm: 3c newton cg"); return t; }
Teuchos::Time& line_search_timer() { static auto& t = timer("viscompm: 3d newton line search"); return t; }
Teuchos::Time& gradient_timer() { static auto& t = timer("viscompm: 3e newton gradient"); return t; }

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

struct GlobalEnergy {
  double value;
  double magnitude;
};

GlobalEnergy global_energy(const implicit::IncrementalPotential& potential, const NodeVectorField& v,
                           const parallel::Communicator& comm) {
  const implicit::EnergyValue local = potential.energy(v);
  if (comm.any(!local.feasible())) return {std::numeric_limits<double>::infinity(), 0.0};
  return {comm.sum(local.value), comm.sum(local.magnitude)};
}

double owned_dot(const NodeVectorField& a, const NodeVectorField& b, std::size_t owned,
                 const parallel::Communicator& comm) {
  double local = 0.0;
  for (std::size_t i = 0; i < owned; ++i) local += a[i].dot(b[i]);
  return comm.sum(local);
}
}  // namespace

double velocity_residual(const implicit::IncrementalPotential& potential, const NodeVectorField& g,
                         const parallel::Communicator& comm) {
  double weighted = 0.0, mass = 0.0;
  for (std::size_t i = 0; i < potential.layout().owned_count; ++i) {
    const double m = potential.mass()[i];
    if (m <= 0.0) continue;
    weighted += g[i].squaredNorm() / m;
    mass += m;
  }
  const double total_mass = comm.sum(mass);
  return total_mass > 0.0 ? std::sqrt(comm.sum(weighted) / total_mass) : 0.0;
}

/// The state of one solve.
struct NewtonSolver::Step {
  const implicit::IncrementalPotential& potential;
  NodeVectorField& v;
  const SystemObserver& observer;
  NewtonReport report;
  bool assembled_this_step = false;
  bool preconditioned_this_step = false;
  NodeVectorField v_trial;
};

NewtonSolver::NewtonSolver(const NewtonSettings& settings, linalg::NewtonSystem& system,
                           const parallel::Communicator& comm)
    : settings_(settings), system_(system), comm_(comm) {}

void NewtonSolver::forget() {
  hessian_kept_ = false;
  refresh_hessian_ = false;
  refresh_preconditioner_ = true;
}

NewtonReport NewtonSolver::solve(const implicit::IncrementalPotential& potential, NodeVectorField& v,
                                 const SystemObserver& observer) {
  Step step{potential, v, observer, {}, false, false, {}};
  NewtonReport& report = step.report;
  report.tolerance = settings_.tolerance * potential.layout().geometry.dx / potential.dt();
  // A Hessian kept from an earlier step is usable only on the same graph and Δt (and only
  // assembled: matrix-free pieces belong to their step's particles).
  if (settings_.hessian_update != HessianUpdate::lagged || system_.matrix_free() ||
      kept_pattern_ != system_.pattern_version() || kept_dt_ != potential.dt())
    hessian_kept_ = false;
  // A preconditioner of another Δt's H (H = M + Δt² K) is refreshed.
  if (preconditioner_dt_ != potential.dt()) refresh_preconditioner_ = true;
  NodeVectorField g, dv;
  for (;;) {
    // Residual: g = ∇E(v), complete on the owned nodes.
    {
      Teuchos::TimeMonitor t(gradient_timer());
      const auto start = std::chrono::steady_clock::now();
      const bool feasible = potential.gradient(v, g);
      report.gradient_seconds += seconds_since(start);
      if (comm_.any(!feasible)) {
        report.failure = "infeasible state";
        break;
      }
    }
    const double residual = velocity_residual(potential, g, comm_);
    if (!report.residual_history.empty() && residual > settings_.refresh_contraction * report.residual_history.back())
      refresh_hessian_ = true;  // a kept H no longer contracts the residual well enough
    report.residual = residual;
    report.residual_history.push_back(residual);

    // Convergence test.
    if (!std::isfinite(residual)) {
      report.failure = "residual is not finite";
      break;
    }
    if (residual <= report.tolerance) {
      report.converged = true;
      break;
    }
    if (report.iterations == settings_.max_iterations) {
      report.failure = "no convergence in " + std::to_string(settings_.max_iterations) + " iterations";
      break;
    }
    // A stop request on any rank abandons the solve (one agreement per iteration).
    if (interrupt_ && comm_.any(interrupt_())) {
      report.interrupted = true;
      report.failure = "interrupted by a stop request";
      break;
    }
    ++report.iterations;

    // Direction H dv = −∇E, then the line search along it (both inside: a failed line search
    // may call for a fresh or projected Hessian).
    if (!direction_and_line_search(step, g, dv)) break;
  }
  if (!report.converged) forget();
  return report;
}

double NewtonSolver::forcing(const Step& step) const {
  if (settings_.linear_tolerance == LinearTolerance::fixed) return system_.default_tolerance();
  const auto& r = step.report.residual_history;
  double eta = settings_.forcing_max;
  if (r.size() >= 2) {
    // Eisenstat–Walker choice 2, with their safeguard against a sudden drop.
    const double previous = step.report.linear_solves.empty() ? settings_.forcing_max
                                                              : step.report.linear_solves.back().tolerance;
    eta = settings_.forcing_gamma * std::pow(r.back() / r[r.size() - 2], settings_.forcing_exponent);
    const double safeguard = settings_.forcing_gamma * std::pow(previous, settings_.forcing_exponent);
    if (safeguard > 0.1) eta = std::max(eta, safeguard);
  }
  // No oversolving near the end: a residual reduction to half the Newton tolerance suffices.
  eta = std::max(eta, 0.5 * step.report.tolerance / r.back());
  return std::clamp(eta, system_.default_tolerance(), settings_.forcing_max);
}

void NewtonSolver::assemble(Step& step, bool project) {
  {
    Teuchos::TimeMonitor t(assemble_timer());
    const double seconds = system_.assemble(step.potential, step.v, project);
    step.report.linear_solves.emplace_back();  // the solve this assembly is for
    step.report.linear_solves.back().operator_seconds = seconds;
  }
  ++step.report.assemblies;
  hessian_kept_ = true;
  kept_projected_ = project;
  kept_dt_ = step.potential.dt();
  kept_pattern_ = system_.pattern_version();
  hessian_baseline_cg_ = -1;
  refresh_hessian_ = false;
  step.assembled_this_step = true;
  // The preconditioner follows the new values as the strategy says.
  const bool setup = !system_.preconditioned() || refresh_preconditioner_ ||
                     settings_.preconditioner_update == PreconditionerUpdate::every_assembly ||
                     (settings_.preconditioner_update == PreconditionerUpdate::every_step && !step.preconditioned_this_step);
  if (setup) {
    Teuchos::TimeMonitor t(precondition_timer());
    step.report.linear_solves.back().setup_seconds = system_.precondition();
    ++step.report.preconditioner_setups;
    preconditioner_dt_ = step.potential.dt();
    preconditioner_baseline_cg_ = -1;
    refresh_preconditioner_ = false;
    step.preconditioned_this_step = true;
  }
}

bool NewtonSolver::direction_and_line_search(Step& step, const NodeVectorField& g, NodeVectorField& dv) {
  NewtonReport& report = step.report;
  const std::size_t owned = step.potential.layout().owned_count;
  NodeVectorField rhs(g.size());
  for (std::size_t i = 0; i < g.size(); ++i) rhs[i] = -g[i];
  const double tolerance = forcing(step);
  const bool may_project = settings_.hessian_projection != HessianProjection::never;
  bool project = settings_.hessian_projection == HessianProjection::always;
  // A fresh H at every iteration, at the first of each step, or when the refresh rule fired.
  bool fresh = settings_.hessian_update == HessianUpdate::every_iteration || !hessian_kept_ || refresh_hessian_ ||
               (settings_.hessian_update == HessianUpdate::every_step && !step.assembled_this_step);
  for (;;) {
    if (fresh) assemble(step, project);
    else report.linear_solves.emplace_back();
    if (step.observer && fresh) step.observer(report.iterations, system_, rhs);
    linalg::LinearSolveReport& solve = report.linear_solves.back();
    {
      Teuchos::TimeMonitor t(cg_timer());
      const linalg::LinearSolveReport cg = system_.solve(rhs, dv, tolerance);
      solve.iterations = cg.iterations;
      solve.relative_residual = cg.relative_residual;
      solve.solve_seconds = cg.solve_seconds;
      solve.setup_seconds += cg.setup_seconds;
      solve.converged = cg.converged;
      solve.tolerance = cg.tolerance;
      solve.preconditioner = cg.preconditioner;
    }
    const bool used_projection = fresh ? project : kept_projected_;
    report.projected_solves += used_projection;
    // The refresh rule: CG slowing down means the kept H or preconditioner has gone stale.
    if (hessian_baseline_cg_ < 0) hessian_baseline_cg_ = solve.iterations;
    else if (solve.iterations > settings_.refresh_growth * hessian_baseline_cg_) refresh_hessian_ = true;
    if (preconditioner_baseline_cg_ < 0) preconditioner_baseline_cg_ = solve.iterations;
    else if (settings_.preconditioner_update == PreconditionerUpdate::lagged &&
             solve.iterations > settings_.refresh_growth * preconditioner_baseline_cg_)
      refresh_preconditioner_ = true;

    step.potential.constraints().project(dv);
    const double slope = -owned_dot(rhs, dv, owned, comm_);  // ∇E·dv
    const bool usable = slope < 0.0 && (solve.converged || used_projection || !may_project);
    if (usable && line_search(step, dv, slope)) return true;
    // A kept H or preconditioner that failed is replaced by a fresh one; a fresh exact H by the
    // projected one.
    const bool preconditioner_kept =
        solve.setup_seconds == 0.0 && settings_.preconditioner_update != PreconditionerUpdate::every_assembly;
    if (!fresh || preconditioner_kept) {
      fresh = true;
      refresh_preconditioner_ = true;
      project = settings_.hessian_projection == HessianProjection::always;
      continue;
    }
    if (used_projection || !may_project) {
      report.failure = usable ? "line search found no decrease" : "the linear solve gave no descent direction";
      return false;
    }
    project = true;
  }
}

bool NewtonSolver::line_search(Step& step, const NodeVectorField& dv, double slope) {
  // Backtracking on E along dv (§5.7: E = +∞ where b_OB or F becomes infeasible); on success v
  // moves to v + α dv. The test allows the rounding of E itself (`Energy rounding`).
  Teuchos::TimeMonitor t(line_search_timer());
  const auto start = std::chrono::steady_clock::now();
  NewtonReport& report = step.report;
  const GlobalEnergy e0 = global_energy(step.potential, step.v, comm_);
  double alpha = 1.0;
  bool accepted = false;
  for (int k = 0; k < settings_.max_line_search_steps; ++k, alpha *= 0.5) {
    step.v_trial = step.v;
    for (std::size_t i = 0; i < step.v.size(); ++i) step.v_trial[i] += alpha * dv[i];
    const GlobalEnergy e = global_energy(step.potential, step.v_trial, comm_);
    if (e.value <= e0.value + settings_.armijo * alpha * slope + settings_.energy_rounding * e0.magnitude) {
      report.step_lengths.push_back(alpha);
      step.v.swap(step.v_trial);
      accepted = true;
      break;
    }
    ++report.backtracks;
  }
  if (accepted && alpha < 1.0) refresh_hessian_ = true;  // the refresh rule: a shortened step
  report.line_search_seconds += seconds_since(start);
  return accepted;
}

std::string NewtonReport::history() const {
  std::ostringstream out;
  out << std::setprecision(2) << "residual/tolerance";
  for (double r : residual_history) out << ' ' << r / tolerance;
  out << "; step lengths";
  for (double a : step_lengths) out << ' ' << a;
  return out.str();
}

}  // namespace viscompm::newton
