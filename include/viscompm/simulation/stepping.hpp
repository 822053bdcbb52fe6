// Advancing a run in time, step by step (§5.5.1 and the choices it leaves open, doc/numerics.md
// "Time step"): before each step the ranks re-partition when their particle counts drift apart,
// Δt is chosen (CFL on particle, collider and inflow speeds, bounded, landing on the target
// time), the TimeIntegrator takes the step — retried here with a smaller Δt when it fails (the
// integrator leaves the particles as they were) — and its statistics are summed; after it, the
// emitters add the layers due by its end, and the caller's after-step callback decides whether to
// go on. A step abandoned on the integrator's interrupt (TimeIntegrator::set_interrupt) ends
// advance_to too, with or without an after-step callback: it cannot loop on a step that is never
// taken.
#pragma once

#include <cstdint>
#include <functional>
#include <iosfwd>
#include <memory>
#include <string>

#include "viscompm/io/solver_log.hpp"
#include "viscompm/simulation/run_setup.hpp"

namespace viscompm::simulation {

struct RunSummary {
  std::int64_t steps = 0;
  std::int64_t newton_iterations = 0;
  std::int64_t linear_iterations = 0;
  std::int64_t retries = 0;
  std::int64_t assemblies = 0;             ///< Hessians assembled (or matrix-free pieces prepared)
  std::int64_t preconditioner_setups = 0;
  double operator_seconds = 0.0;           ///< in assembly (or the matrix-free set-up), all solves
  double preconditioner_seconds = 0.0;     ///< in preconditioner set-up
  double cg_seconds = 0.0;                 ///< in CG
  double line_search_seconds = 0.0;
  std::int64_t graph_builds = 0;         ///< node partitions (and Hessian graphs) built, all steps
  std::int64_t ghost_particle_steps = 0;  ///< Σ over steps of the global count of ghost particles
  std::int64_t particles_deleted = 0;
  std::int64_t particles_migrated = 0;  ///< sent between ranks, all steps
  std::int64_t shared_node_steps = 0;   ///< Σ over steps of the global count of ghost nodes
  std::int64_t owned_node_steps = 0;    ///< Σ over steps of the global count of nodes
  int rebalances = 0;
  double wall_seconds = 0.0;
  int stop_signal = 0;          ///< the signal that stopped the run early (0: it ran to the end)
  std::string stop_checkpoint;  ///< the checkpoint written when it stopped early
};

/// Called after every step on every rank (collective): true stops advancing.
using AfterStep = std::function<bool()>;

/// How one step of advance_to ended: taken (perhaps after retries with a smaller Δt), or
/// abandoned on the integrator's interrupt (the state is that of the step's start).
enum class StepOutcome { taken, interrupted };

class Stepper {
 public:
  /// Steps `state` (which must outlive the stepper) with the scene's step control.
  Stepper(const scene::SceneConfig& scene, SimulationState& state, const grid::GridGeometry& geometry,
          grid::KernelOrder order, const materials::MaterialList& materials, const boundary::Boundary& boundary,
          const linalg::SolverConfiguration& solver, const parallel::Communicator& comm);
  Stepper(const Stepper&) = delete;
  Stepper& operator=(const Stepper&) = delete;

  /// Advances to time t_end. Throws SimulationError if a step fails at the smallest Δt. Returns
  /// false when `after_step` asked to stop or a step was interrupted (TimeIntegrator::set_interrupt;
  /// `after_step` is still called, so that the ranks can agree on the stop and checkpoint): the
  /// state is then that after the last step taken. It never retries an interrupted step.
  bool advance_to(double t_end, RunSummary& summary, std::ostream* log = nullptr, const AfterStep& after_step = {});
  /// The Δt the next step would try (CFL, bounds), before landing on the target time.
  double suggested_time_step() const;
  /// Adds the particles the emitters owe by the state's time (every rank counts every layer and
  /// keeps the particles it owns), held inside the grid.
  void emit_particles();
  /// Where each linear solve is recorded (solver.csv), or nullptr.
  void set_solver_log(io::SolverLog* log) { solver_log_ = log; }
  TimeIntegrator& integrator() { return *integrator_; }

 private:
  const scene::SceneConfig& scene_;
  SimulationState& state_;
  const grid::GridGeometry& geometry_;
  grid::KernelOrder order_;
  const boundary::Boundary& boundary_;
  parallel::Communicator comm_;
  std::unique_ptr<TimeIntegrator> integrator_;
  io::SolverLog* solver_log_ = nullptr;
  int retries_reported_ = 0;
  double fastest_wave_speed_ = 0.0;  ///< the largest Material::wave_speed of the scene's materials

  /// What a step failing at the smallest Δt may owe to a parameter: a prescribed motion faster
  /// than every material's elastic waves ("; likely cause: parameter '...' ..."), or "".
  std::string likely_cause() const;

  /// Re-partitions the grid when the particle counts of the ranks drift apart (Grid/Rebalance
  /// threshold) and migrates the particles (collective).
  void rebalance_if_needed(RunSummary& summary, std::ostream* log);
  /// One step of length dt, retried with smaller Δt until it is taken (or interrupted).
  StepOutcome take_step(double dt, RunSummary& summary, std::ostream* log);
  /// Adds an attempt's counts (Newton, CG, timings) to the summary and solver.csv.
  void record_attempt(const StepReport& report, RunSummary& summary);
};

}  // namespace viscompm::simulation
