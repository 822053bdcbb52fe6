#include "viscompm/newton/newton_solver.hpp"

#include <Teuchos_TimeMonitor.hpp>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <iomanip>
#include <limits>
#include <sstream>

namespace viscompm::newton {

namespace {
// No pattern: a system not set up yet.
constexpr std::uint64_t no_pattern = std::numeric_limits<std::uint64_t>::max();

// The phases' timers (doc/architecture.md), all here.
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
  NodeVectorField v_trial;
  // L-BFGS: the last accepted step and the gradient it started from (the next pair, once the new
  // gradient is known), and the iterations since H₀ was built.
  NodeVectorField lbfgs_step, lbfgs_gradient;
  int lbfgs_age = -1;  // -1: no H₀ this step
};

NewtonSolver::NewtonSolver(const NewtonSettings& settings, linalg::NewtonSystem& system,
                           const parallel::Communicator& comm)
    : settings_(settings), comm_(comm), lbfgs_(settings.lbfgs_pairs) {
  owned_systems_.push_back(make_linear_system(system));
  systems_.push_back(owned_systems_.back().get());
  rules_.emplace_back(settings);
  begun_.assign(1, false);
  set_up_for_.assign(1, no_pattern);
  seconds_per_iteration_.assign(1, -1.0);
}

NewtonSolver::NewtonSolver(const NewtonSettings& settings, LinearSystem& system, const parallel::Communicator& comm)
    : settings_(settings), systems_{&system}, comm_(comm), lbfgs_(settings.lbfgs_pairs) {
  rules_.emplace_back(settings);
  begun_.assign(1, false);
  set_up_for_.assign(1, no_pattern);
}

NewtonSolver::NewtonSolver(const NewtonSettings& settings, const std::vector<linalg::NewtonSystem*>& candidates,
                           const linalg::SolverChoiceSettings& choice, const parallel::Communicator& comm)
    : settings_(settings), comm_(comm), lbfgs_(settings.lbfgs_pairs) {
  for (linalg::NewtonSystem* candidate : candidates) {
    owned_systems_.push_back(make_linear_system(*candidate));
    systems_.push_back(owned_systems_.back().get());
    rules_.emplace_back(settings);
  }
  begun_.assign(systems_.size(), false);
  set_up_for_.assign(systems_.size(), no_pattern);
  seconds_per_iteration_.assign(systems_.size(), -1.0);
  choice_.emplace(static_cast<int>(systems_.size()), choice);
}

NewtonSolver::~NewtonSolver() = default;

void NewtonSolver::forget() {
  for (auto& rules : rules_) rules.forget();
  exact_failed_first_ = false;
}

NewtonReport NewtonSolver::solve(const implicit::IncrementalPotential& potential, NodeVectorField& v,
                                 const SystemObserver& observer) {
  Step step{potential, v, observer, {}, {}, {}, {}, -1};
  NewtonReport& report = step.report;
  report.tolerance = settings_.tolerance * potential.layout().geometry.dx / potential.dt();
  std::fill(begun_.begin(), begun_.end(), false);
  lbfgs_.clear();
  NodeVectorField g, dv;
  // A counted loop: `Max iterations` directions at most, each after the residual and its tests;
  // the residual after the last direction is tested once more.
  const auto finish = [&]() -> NewtonReport {
    if (!report.converged) forget();
    if (choice_ && !report.interrupted) choice_->step_ended();
    return report;
  };
  for (int direction = 0; direction < settings_.max_iterations; ++direction) {
    if (residual_settles(step, g) || stop_requested(step)) return finish();
    ++report.iterations;
    bool moved = false;
    do {
      direction_start_ = std::chrono::steady_clock::now();
      fresh_setup_seconds_ = 0.0;
      abandoned_ = false;
      select_candidate(step);
      // Direction, then the line search along it (both inside: a failed line search may call for a
      // fresh or projected Hessian).
      moved = settings_.method == Method::lbfgs ? lbfgs_direction_and_line_search(step, g, dv)
                                                : newton_direction_and_line_search(step, g, dv);
      // What the direction cost, the slowest rank's, so that every rank chooses the same. A
      // direction given up at its budget is computed again by the candidate the choice names.
      if (!choice_) break;
      const double seconds = comm_.max(seconds_since(direction_start_)), fresh = comm_.max(fresh_setup_seconds_);
      if (abandoned_) choice_->direction_abandoned(seconds, fresh);
      else choice_->direction_solved(seconds, fresh);
    } while (abandoned_);
    if (!moved) return finish();
  }
  if (!residual_settles(step, g) && report.failure.empty())
    report.failure = "no convergence in " + std::to_string(settings_.max_iterations) + " iterations";
  return finish();
}

void NewtonSolver::select_candidate(Step& step) {
  const int next = choice_ ? choice_->next() : 0;
  if (next != current_) lbfgs_.clear();  // L-BFGS pairs belong to the H₀ they were built with
  if (next != current_ && step.lbfgs_age >= 0) step.lbfgs_age = -1;
  current_ = next;
  if (begun_[current_]) return;
  system().prepare();
  rules().begin_solve(step.potential.dt(), system().pattern_version(), system().matrix_free());
  begun_[current_] = true;
}

bool NewtonSolver::residual_settles(Step& step, NodeVectorField& g) {
  NewtonReport& report = step.report;
  // Residual: g = ∇E(v), complete on the owned nodes.
  {
    Teuchos::TimeMonitor t(gradient_timer());
    const auto start = std::chrono::steady_clock::now();
    const bool feasible = step.potential.gradient(step.v, g);
    report.gradient_seconds += seconds_since(start);
    if (comm_.any(!feasible)) {
      report.failure = "infeasible state";
      return true;
    }
  }
  const double residual = velocity_residual(step.potential, g, comm_);
  if (!report.residual_history.empty()) rules().residual(report.residual_history.back(), residual);
  report.residual = residual;
  report.residual_history.push_back(residual);
  // Convergence test.
  if (!std::isfinite(residual)) {
    report.failure = "residual is not finite";
    return true;
  }
  report.converged = residual <= report.tolerance;
  return report.converged;
}

bool NewtonSolver::stop_requested(Step& step) const {
  // One agreement across ranks per question.
  if (!interrupt_ || !comm_.any(interrupt_())) return false;
  step.report.interrupted = true;
  step.report.failure = "interrupted by a stop request";
  return true;
}

double NewtonSolver::forcing(const Step& step) const {
  if (settings_.linear_tolerance == LinearTolerance::fixed) return system().default_tolerance();
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
  return std::clamp(eta, system().default_tolerance(), settings_.forcing_max);
}

void NewtonSolver::assemble(Step& step, bool project) {
  Teuchos::TimeMonitor t(assemble_timer());
  const double seconds = system().assemble(step.potential, step.v, project);
  step.report.linear_solves.back().operator_seconds += seconds;
  ++step.report.assemblies;
  rules().assembled(project);
}

void NewtonSolver::precondition(Step& step) {
  Teuchos::TimeMonitor t(precondition_timer());
  const double seconds = system().precondition();
  step.report.linear_solves.back().setup_seconds += seconds;
  // A set-up on a pattern this system has not been set up on builds its preconditioner anew.
  if (set_up_for_[current_] != system().pattern_version()) fresh_setup_seconds_ += seconds;
  set_up_for_[current_] = system().pattern_version();
  ++step.report.preconditioner_setups;
  rules().preconditioned();
}

bool NewtonSolver::newton_direction_and_line_search(Step& step, const NodeVectorField& g, NodeVectorField& dv) {
  NodeVectorField rhs(g.size());
  for (std::size_t i = 0; i < g.size(); ++i) rhs[i] = -g[i];
  const double tolerance = forcing(step);
  const bool adaptive = settings_.hessian_projection == HessianProjection::adaptive;
  const bool always = settings_.hessian_projection == HessianProjection::always;
  // The attempts, in order: (1) as the strategy says — a kept or fresh H, exact unless projection
  // is always on or the kept H is projected; (2) a fresh H and preconditioner, if (1) used anything
  // kept; (3) the fresh projected H, if the last H was exact and projection is adaptive. Where (1)
  // was a fresh exact H with a kept preconditioner and projection is adaptive, (2) is the projected
  // H with that preconditioner (SPD, so CG needs no new one: a set-up spared, often the price of a
  // whole direction) and (3) the projected H with a fresh preconditioner.
  Attempt attempt{rules().assemble_now(), always};
  if (!attempt.fresh) attempt.project = rules().kept_projected();
  // Once an exact H has failed as a step's first direction, later steps' first directions start
  // from the projected H (the step's start is where the exact H is indefinite, and its failed
  // attempt cost an assembly and a set-up); later directions of a step still try the exact H.
  const bool step_start_fresh = adaptive && step.report.iterations == 1 && attempt.fresh;
  if (step_start_fresh && exact_failed_first_) attempt.project = true;
  bool projected_with_kept_preconditioner = false;
  for (int k = 0; k < direction_attempts; ++k) {
    if (k > 0 && stop_requested(step)) return false;
    bool used_kept = false;
    const bool ok = try_newton_direction(step, rhs, tolerance, attempt, dv, used_kept);
    if (k == 0 && step_start_fresh && !attempt.project && !abandoned_) exact_failed_first_ = !ok;
    if (ok) return true;
    if (abandoned_) return false;  // a solve out of the choice's budget: not a failure of the step
    if (used_kept && adaptive && attempt.fresh && !attempt.project && !projected_with_kept_preconditioner) {
      attempt = {true, true};
      projected_with_kept_preconditioner = true;
      continue;  // the preconditioner stays
    }
    if (projected_with_kept_preconditioner) {
      attempt = {true, true};
    } else if (used_kept) {
      attempt = {true, always || (attempt.project && !adaptive)};
    } else if (!attempt.project && adaptive) {
      attempt = {true, true};
    } else {
      break;
    }
    rules().demand_fresh();  // the next attempt sets up its own preconditioner
  }
  if (step.report.failure.empty()) {
    const linalg::LinearSolveReport& last = step.report.linear_solves.back();
    step.report.failure = "no direction with sufficient decrease (the last: " +
                          std::string(last.converged ? "line search failed"
                                                     : "linear solve failed" + (last.failure.empty() ? std::string()
                                                                                                      : ": " + last.failure)) +
                          ")";
  }
  return false;
}

bool NewtonSolver::try_newton_direction(Step& step, const NodeVectorField& rhs, double tolerance,
                                        const Attempt& attempt, NodeVectorField& dv, bool& used_kept) {
  NewtonReport& report = step.report;
  report.linear_solves.emplace_back();  // the solve of this attempt
  if (attempt.fresh) {
    assemble(step, attempt.project);
    if (step.observer && system().newton_system()) step.observer(report.iterations, *system().newton_system(), rhs);
  }
  if (rules().setup_now()) precondition(step);
  used_kept = !attempt.fresh || !rules().preconditioner_matches_hessian();
  linalg::LinearSolveReport& solve = report.linear_solves.back();
  {
    Teuchos::TimeMonitor t(cg_timer());
    // The solve's report, with this attempt's assembly and set-up times kept.
    const double operator_seconds = solve.operator_seconds, setup_seconds = solve.setup_seconds;
    const int cap = budget_iteration_cap();
    solve = system().solve(rhs, dv, tolerance, cap);
    solve.operator_seconds = operator_seconds;
    solve.setup_seconds = setup_seconds;
    if (choice_ && solve.iterations > 0)
      seconds_per_iteration_[current_] = comm_.max(solve.solve_seconds / solve.iterations);
    // Every rank ran the same iterations: the same answer everywhere.
    abandoned_ = cap > 0 && !solve.converged && solve.failure.empty() && solve.iterations >= cap;
    if (abandoned_) solve.failure = "trial budget of " + std::to_string(cap) + " iterations spent";
  }
  if (abandoned_) return false;
  report.projected_solves += attempt.project;
  rules().solved(solve.iterations, solve.tolerance);

  step.potential.constraints().project(dv);
  const double slope = -owned_dot(rhs, dv, step.potential.layout().owned_count, comm_);  // ∇E·dv
  // An unconverged solve of the exact H may point anywhere; with the projected H (SPD) any CG
  // iterate is a descent direction.
  const bool usable = slope < 0.0 && (solve.converged || attempt.project ||
                                      settings_.hessian_projection == HessianProjection::never);
  return usable && line_search(step, dv, slope);
}

int NewtonSolver::budget_iteration_cap() const {
  // Under a measured choice the solve may take the iterations its measured cost per iteration
  // affords within the choice's budget (at least one): on trial, before its candidate has lost;
  // the chosen one, before its step would start a trial at once. Without a bound, the file's limit.
  if (!choice_ || seconds_per_iteration_[current_] <= 0.0) return 0;
  const double budget = choice_->direction_budget(comm_.max(seconds_since(direction_start_)), comm_.max(fresh_setup_seconds_));
  if (!std::isfinite(budget)) return 0;
  return static_cast<int>(std::clamp(std::floor(budget / seconds_per_iteration_[current_]), 1.0, 1e9));
}

void NewtonSolver::rebuild_initial_inverse(Step& step) {
  step.report.linear_solves.back().preconditioner = system().label();
  assemble(step, true);
  precondition(step);
  lbfgs_.clear();
  step.lbfgs_age = 0;
}

bool NewtonSolver::lbfgs_direction_and_line_search(Step& step, const NodeVectorField& g, NodeVectorField& dv) {
  NewtonReport& report = step.report;
  const std::size_t owned = step.potential.layout().owned_count;
  const auto& constraints = step.potential.constraints();
  const LbfgsMemory::Dot dot = [&](const NodeVectorField& a, const NodeVectorField& b) {
    return owned_dot(a, b, owned, comm_);
  };
  // The gradient in the constrained subspace, and the pair of the last accepted step.
  NodeVectorField gradient = g;
  constraints.project(gradient);
  if (step.lbfgs_age > 0) {
    NodeVectorField y(gradient.size());
    for (std::size_t i = 0; i < y.size(); ++i) y[i] = gradient[i] - step.lbfgs_gradient[i];
    lbfgs_.add(std::move(step.lbfgs_step), std::move(y), dot);
  }
  const LbfgsMemory::InitialInverse initial = [&](const NodeVectorField& r, NodeVectorField& z) {
    system().apply_preconditioner(r, z);
    constraints.project(z);
  };
  // At most two tries: with the H₀ at hand, then (if it was built at an earlier iteration) with
  // H₀ rebuilt at the current state and the pairs forgotten.
  for (int k = 0; k < 2; ++k) {
    if (k > 0 && stop_requested(step)) return false;
    report.linear_solves.emplace_back();
    linalg::LinearSolveReport& row = report.linear_solves.back();
    const bool rebuild = step.lbfgs_age < 0 || k > 0 ||
                         (settings_.lbfgs_rebuild > 0 && step.lbfgs_age >= settings_.lbfgs_rebuild);
    if (rebuild) rebuild_initial_inverse(step);
    {
      Teuchos::TimeMonitor t(cg_timer());
      const auto start = std::chrono::steady_clock::now();
      lbfgs_.direction(gradient, dv, dot, initial, system().unpreconditioned());
      constraints.project(dv);
      row.solve_seconds = seconds_since(start);
    }
    // One preconditioner application stands for the linear solve (solver.csv).
    row.iterations = 1;
    row.relative_residual = std::numeric_limits<double>::quiet_NaN();
    row.converged = true;
    row.preconditioner = system().label();
    ++report.projected_solves;
    const double slope = dot(gradient, dv);
    if (slope < 0.0 && line_search(step, dv, slope)) {
      step.lbfgs_step = dv;
      const double alpha = report.step_lengths.back();
      for (auto& x : step.lbfgs_step) x *= alpha;
      step.lbfgs_gradient = std::move(gradient);
      ++step.lbfgs_age;
      return true;
    }
    if (rebuild) break;  // a fresh H₀ failed: nothing fresher to try
  }
  report.failure = "L-BFGS found no direction with sufficient decrease";
  return false;
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
  for (int k = 0; k < settings_.max_line_search_steps; ++k) {
    trial_point(step, dv, alpha);
    const GlobalEnergy e = global_energy(step.potential, step.v_trial, comm_);
    accepted = e.value <= e0.value + settings_.armijo * alpha * slope + settings_.energy_rounding * e0.magnitude;
    if (accepted) break;
    ++report.backtracks;
    alpha *= 0.5;
  }
  // Near the tolerance E's rounding may exceed any decrease a step can make: the residual decides.
  if (!accepted && report.residual <= settings_.residual_fallback * report.tolerance)
    accepted = residual_decrease(step, dv, alpha);
  if (accepted) {
    report.step_lengths.push_back(alpha);
    step.v.swap(step.v_trial);
    rules().line_search_step(alpha);
  }
  report.line_search_seconds += seconds_since(start);
  return accepted;
}

void NewtonSolver::trial_point(Step& step, const NodeVectorField& dv, double alpha) const {
  step.v_trial = step.v;
  for (std::size_t i = 0; i < step.v.size(); ++i) step.v_trial[i] += alpha * dv[i];
}

bool NewtonSolver::residual_decrease(Step& step, const NodeVectorField& dv, double& alpha) {
  NodeVectorField g;
  alpha = 1.0;
  for (int k = 0; k < settings_.max_line_search_steps; ++k) {
    trial_point(step, dv, alpha);
    const bool feasible = step.potential.gradient(step.v_trial, g);
    if (!comm_.any(!feasible) && velocity_residual(step.potential, g, comm_) < step.report.residual) {
      ++step.report.residual_fallbacks;
      return true;
    }
    ++step.report.backtracks;
    alpha *= 0.5;
  }
  return false;
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
