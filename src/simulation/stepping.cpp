#include "viscompm/simulation/stepping.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <optional>
#include <string>
#include <ostream>
#include <sstream>

#include "viscompm/core/error.hpp"
#include "viscompm/linalg/rcb_partition.hpp"
#include "viscompm/parallel/migration.hpp"

namespace viscompm::simulation {

namespace {
// Step control: choices §5.5.1 leaves open (doc/numerics.md, "Time step"). The growth and
// reduction factors of Δt are scene parameters (Simulation/Time step growth, ... reduction).
/// advance_to has reached t_end when within this relative distance of it (round-off of Σ Δt).
constexpr double end_tolerance = 1e-14;
/// A step this close (relative) to the time left before the frame is stretched to land on it.
constexpr double landing_tolerance = 1e-9;
/// No sliver step before a frame: a step longer than this fraction of the time left is
/// shortened to it, so that the last two steps share the remainder.
constexpr double sliver_fraction = 0.5;
/// Re-partition again only when the imbalance exceeds what the last re-partition reached by
/// this factor (cells are indivisible: a re-partition cannot always reach the threshold).
constexpr double rebalance_slack = 1.05;
/// Retries shown in the log; later ones are only counted.
constexpr int retries_logged = 10;
}  // namespace

Stepper::Stepper(const scene::SceneConfig& scene, SimulationState& state, const grid::GridGeometry& geometry,
                 grid::KernelOrder order, const materials::MaterialList& materials, const boundary::Boundary& boundary,
                 const linalg::SolverConfiguration& solver, const parallel::Communicator& comm)
    : scene_(scene),
      state_(state),
      geometry_(geometry),
      order_(order),
      boundary_(boundary),
      comm_(comm),
      integrator_(std::make_unique<TimeIntegrator>(comm, geometry, order, *state.decomposition,
                                                   integrator_settings(scene), materials, boundary, solver)) {
  for (const auto& m : materials) fastest_wave_speed_ = std::max(fastest_wave_speed_, m->wave_speed());
}

std::string Stepper::likely_cause() const {
  // A motion the scene prescribes faster than every elastic wave of its materials: what it
  // drives cannot carry the motion away (it piles up, folds, inverts — an infeasible state), at
  // any Δt. No time-step criterion tells this at read time (each step resolves the motion), so
  // the failure names it.
  scene::PrescribedMotion fastest;
  try {
    fastest = scene::fastest_prescribed_motion(scene_);
  } catch (const std::exception&) {
    return "";  // a scene built in code with shapes the reader would not take: no hint
  }
  if (!(fastest_wave_speed_ > 0.0) || !(fastest.speed > fastest_wave_speed_)) return "";
  std::ostringstream cause;
  cause.precision(3);
  cause << "; likely cause: parameter '" << fastest.parameter << "' prescribes up to " << fastest.speed << " m/s, "
        << fastest.speed / fastest_wave_speed_ << " times the fastest elastic wave of the materials ("
        << fastest_wave_speed_ << " m/s), faster than they can follow";
  return cause.str();
}

void Stepper::emit_particles() {
  std::size_t added = 0;
  const int rank = comm_.rank();
  for (auto& emitter : state_.emitters)
    added += emitter.emit(
        state_.time, [&](const Vec3& x) { return parallel::particle_owner(*state_.decomposition, geometry_, order_, x) == rank; },
        state_.particles);
  if (added > 0) boundary_.clamp_particles(geometry_, state_.particles.position);
}

double Stepper::suggested_time_step() const {
  double speed = 0.0;
  for (const Vec3& v : state_.particles.velocity) speed = std::max(speed, v.norm());
  for (const auto& c : boundary_.colliders()) speed = std::max(speed, c.max_speed());
  for (const auto& e : state_.emitters) speed = std::max(speed, e.spec().velocity.norm());
  speed = comm_.max(speed);
  double dt = std::min(state_.time_step_cap, scene_.simulation.max_time_step);
  if (speed > 0.0) dt = std::min(dt, scene_.simulation.cfl * geometry_.dx / speed);
  return dt;
}

void Stepper::rebalance_if_needed(RunSummary& summary, std::ostream* log) {
  const double threshold = scene_.grid.rebalance_threshold;
  if (threshold <= 0.0 || comm_.size() == 1) return;
  auto& particles = state_.particles;
  const double before = parallel::imbalance(comm_, particles.size());
  // Re-partition when the threshold is crossed, but not again while the imbalance stays at what
  // the last re-partition could reach (cells are indivisible).
  if (before <= std::max(threshold, rebalance_slack * state_.balanced_imbalance)) return;
  auto candidate = linalg::make_rcb_decomposition(comm_, geometry_, particles);
  // Keep the new partition only if it balances better (cells are indivisible: on coarse grids
  // the bisection's cut may land where it cannot help).
  std::vector<double> counts(comm_.size(), 0.0);
  for (const Vec3& x : particles.position) counts[parallel::particle_owner(*candidate, geometry_, order_, x)] += 1.0;
  MPI_Allreduce(MPI_IN_PLACE, counts.data(), comm_.size(), MPI_DOUBLE, MPI_SUM, comm_.comm());
  const double total = std::accumulate(counts.begin(), counts.end(), 0.0);
  const double predicted = *std::max_element(counts.begin(), counts.end()) / (total / comm_.size());
  if (predicted >= before) {
    state_.balanced_imbalance = before;
    return;
  }
  state_.decomposition = std::move(candidate);
  integrator_->set_decomposition(*state_.decomposition);
  parallel::migrate_particles(comm_, *state_.decomposition, geometry_, order_, particles);
  ++summary.rebalances;
  const double after = parallel::imbalance(comm_, particles.size());
  state_.balanced_imbalance = after;
  if (log && comm_.is_root())
    *log << "  step " << state_.step + 1 << ": rebalanced (" << state_.decomposition->describe()
         << "), particle imbalance " << before << " -> " << after << "\n";
}

bool Stepper::advance_to(double t_end, RunSummary& summary, std::ostream* log, const AfterStep& after_step) {
  while (state_.time < t_end * (1.0 - end_tolerance)) {
    rebalance_if_needed(summary, log);
    double dt = suggested_time_step();
    const double remaining = t_end - state_.time;
    if (dt >= remaining * (1.0 - landing_tolerance)) dt = remaining;
    else if (dt > sliver_fraction * remaining) dt = sliver_fraction * remaining;
    if (take_step(dt, summary, log) == StepOutcome::interrupted) {
      // Abandoned (time and step unchanged): the caller agrees on the stop, and the step is not
      // tried again here (with an interrupt that stays set, it never would be taken).
      if (after_step) after_step();
      return false;
    }
    // The layers due by the end of the step, before a frame can be written (doc/scenes.md).
    emit_particles();
    if (after_step && after_step()) return false;
  }
  state_.time = t_end;
  return true;
}

void Stepper::record_attempt(const StepReport& report, RunSummary& summary) {
  const auto& newton = report.newton;
  for (std::size_t k = 0; k < newton.linear_solves.size(); ++k) {
    const auto& solve = newton.linear_solves[k];
    if (solver_log_) solver_log_->record(state_.step + 1, static_cast<int>(k + 1), solve);
    summary.linear_iterations += solve.iterations;
    summary.operator_seconds += solve.operator_seconds;
    summary.preconditioner_seconds += solve.setup_seconds;
    summary.cg_seconds += solve.solve_seconds;
  }
  summary.newton_iterations += newton.iterations;
  summary.assemblies += newton.assemblies;
  summary.preconditioner_setups += newton.preconditioner_setups;
  summary.line_search_seconds += newton.line_search_seconds;
  summary.graph_builds += report.partition_rebuilt;
  if (!report.taken) return;
  summary.ghost_particle_steps += comm_.sum(static_cast<std::int64_t>(report.ghost_particles));
  summary.particles_deleted += comm_.sum(static_cast<std::int64_t>(report.particles_deleted));
  summary.particles_migrated += comm_.sum(static_cast<std::int64_t>(report.particles_sent));
  summary.shared_node_steps += comm_.sum(static_cast<std::int64_t>(report.shared_nodes));
  summary.owned_node_steps += comm_.sum(static_cast<std::int64_t>(report.owned_nodes));
}

StepOutcome Stepper::take_step(double dt, RunSummary& summary, std::ostream* log) {
  std::optional<std::string> dump_prefix;
  for (double s : scene_.output.matrix_market_steps)
    if (static_cast<std::int64_t>(s) == state_.step + 1)
      dump_prefix = scene_.output.directory + "/newton_step_" + std::to_string(state_.step + 1);
  for (;;) {
    // A step that is not taken leaves the particles as they were (TimeIntegrator::step).
    const StepReport report = integrator_->step(state_.particles, state_.time, dt, dump_prefix);
    record_attempt(report, summary);
    if (report.newton.interrupted) return StepOutcome::interrupted;  // the state stays that of the step's start
    if (report.taken) break;
    ++summary.retries;
    const double reduction = scene_.simulation.time_step_reduction;
    if (dt * reduction < scene_.simulation.min_time_step)
      throw SimulationError("at t = " + std::to_string(state_.time) + " with the smallest Δt: " + report.failure +
                            "; the last frame written is frame " + std::to_string(state_.frame) + likely_cause());
    if (log && comm_.is_root() && ++retries_reported_ <= retries_logged)
      *log << "  step " << state_.step + 1 << ": " << report.failure << " at Δt = " << dt << ", retrying with Δt × "
           << reduction << (report.newton.converged ? std::string() : " [" + report.newton.history() + "]")
           << (retries_reported_ == retries_logged ? " (further retries are counted, not shown)" : "") << "\n";
    dt *= reduction;
    state_.time_step_cap = dt;
  }
  state_.time += dt;
  ++state_.step;
  ++summary.steps;
  state_.time_step_cap = std::min(scene_.simulation.time_step_growth * state_.time_step_cap, scene_.simulation.max_time_step);
  return StepOutcome::taken;
}

}  // namespace viscompm::simulation
