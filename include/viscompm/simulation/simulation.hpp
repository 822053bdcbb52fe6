// A run of a scene: set-up (grid, decomposition, materials, particles, colliders), then frames
// of adaptive time steps (CFL, landing on frame times, Δt reduced and the step retried when
// Newton fails or the step produces non-finite values), output and a progress line per frame on
// rank 0. A run stops early, with a checkpoint, when a signal asks it to (stop_request.hpp).
#pragma once

#include <chrono>
#include <iosfwd>
#include <memory>

#include "viscompm/boundary/colliders.hpp"
#include "viscompm/io/frame_writer.hpp"
#include "viscompm/io/solver_log.hpp"
#include "viscompm/linalg/linear_solver.hpp"
#include "viscompm/materials/material.hpp"
#include "viscompm/parallel/decomposition.hpp"
#include "viscompm/particles/emitter.hpp"
#include "viscompm/scene/scene.hpp"
#include "viscompm/simulation/time_integrator.hpp"

namespace viscompm::simulation {

/// The scene's materials, in its order, from the registry.
materials::MaterialList make_materials(const scene::SceneConfig& scene);
/// Throws InputError naming 'Grid/Cell size' when the scene's particles cannot fit in the memory
/// of the ranks of `comm` (an estimate made before anything is sampled; collective).
void check_memory(const scene::SceneConfig& scene, const parallel::Communicator& comm);

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

class Simulation {
 public:
  /// A run of `scene`; with `restart_file`, the state comes from that checkpoint instead of the
  /// scene's bodies (InputError if it does not fit the scene).
  Simulation(const scene::SceneConfig& scene, const linalg::SolverConfiguration& solver,
             const parallel::Communicator& comm, const std::string& restart_file = "");
  /// The same with the materials built by the caller, one per scene material in the scene's
  /// order (models defined outside the registry: a library user's, or a test's).
  Simulation(const scene::SceneConfig& scene, materials::MaterialList materials,
             const linalg::SolverConfiguration& solver, const parallel::Communicator& comm,
             const std::string& restart_file = "");

  /// Writes frame 0 (unless restarted), then every remaining frame of the scene, with checkpoints
  /// as the scene asks, logging progress to `log` on rank 0. After every step the ranks agree on
  /// a stop request (SIGTERM, SIGINT): the run then writes a checkpoint and returns with
  /// RunSummary::stop_signal set. A failed write (disk full, directory gone) is SimulationError;
  /// every file written before stays intact.
  RunSummary run(std::ostream& log);
  /// Writes DIR/checkpoint_NNNNN.h5 for the current frame; returns its path. The run then
  /// continues as one restarted from it would (TimeIntegrator::reset_reuse).
  std::string write_checkpoint();
  /// Advances to time t_end with adaptive steps (no output). Throws SimulationError if a step
  /// fails at the smallest Δt. Inside run(), returns false when it stopped early on a request.
  bool advance_to(double t_end, RunSummary& summary, std::ostream* log = nullptr);

  double time() const { return time_; }
  std::int64_t step_count() const { return step_; }
  particles::ParticleSet& particles() { return particles_; }
  const materials::MaterialList& materials() const { return materials_; }
  TimeIntegrator& integrator() { return *integrator_; }
  const grid::GridGeometry& grid() const { return geometry_; }
  const boundary::Boundary& boundary() const { return boundary_; }

  /// Adds the particles the emitters owe by the current time (collective in effect: every rank
  /// counts every layer and keeps the particles it owns).
  void emit_particles();
  const std::vector<particles::Emitter>& emitters() const { return emitters_; }
  /// Mass delivered by all emitters so far.
  double emitted_mass() const;
  /// What a frame written now holds besides the particles (collider surfaces, emitted mass).
  io::FrameExtras frame_extras() const;
  /// Writes DIR/surface_NNNNN.{obj,vdb}: the particles' surface (Output/Surface voxel size).
  void write_surface(int frame) const;

 private:
  scene::SceneConfig scene_;
  parallel::Communicator comm_;
  grid::GridGeometry geometry_;
  grid::KernelOrder order_;
  std::unique_ptr<parallel::Decomposition> decomposition_;
  materials::MaterialList materials_;
  boundary::Boundary boundary_;
  particles::ParticleSet particles_;
  std::vector<particles::Emitter> emitters_;
  std::unique_ptr<TimeIntegrator> integrator_;
  std::unique_ptr<io::SolverLog> solver_log_;  ///< open during run()
  double time_ = 0.0;
  std::int64_t step_ = 0;
  int frame_ = 0;                 ///< last frame written (or restarted from)
  bool restarted_ = false;
  double time_step_cap_;          ///< reduced when a step fails, grows per success
  int retries_reported_ = 0;
  double balanced_imbalance_ = 1.0;  ///< imbalance right after the last re-partition
  std::vector<io::FrameInfo> frames_;
  particles::ParticleSet before_step_;  ///< the state a step that went non-finite is retried from
  bool in_run_ = false;                 ///< advance_to is inside run(): stop requests apply
  std::chrono::steady_clock::time_point last_checkpoint_time_;
  std::string wall_checkpoint_;         ///< the last checkpoint written between frames by this run

  /// Re-partitions the grid when the particle counts of the ranks drift apart (Grid/Rebalance
  /// threshold) and migrates the particles (collective).
  void rebalance_if_needed(RunSummary& summary, std::ostream* log);
  /// The Δt the next step would try (CFL, bounds), before landing on the frame time.
  double suggested_time_step() const;
  /// One step of length dt from time_, retried with smaller Δt until it succeeds.
  void take_step(double dt, RunSummary& summary, std::ostream* log);
  /// True on every rank if any rank holds a non-finite particle value.
  bool state_is_finite() const;
  /// After a step inside run(): agrees on stop requests, wall-clock checkpoints and the solver
  /// log's health; true if the run must stop (its checkpoint written).
  bool stop_requested(RunSummary& summary, std::ostream* log);
  /// Writes DIR/NAME and resets the integrator's reuse, as write_checkpoint.
  std::string write_checkpoint_file(const std::string& name);
  void write_frame(int frame);
};

}  // namespace viscompm::simulation
