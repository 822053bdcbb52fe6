// A run of a scene, in three parts: the set-up (run_setup.hpp: memory estimate, materials, grid,
// boundary, the initial or restarted state), the stepping (stepping.hpp: Δt control, step retries,
// rebalancing, emission) and, here, the run driver: frames, checkpoints and surfaces written,
// a progress line per frame on rank 0, and after every step — through the stepping's after-step
// callback — the ranks' agreement on stop requests (stop_request.hpp), wall-clock checkpoints and
// the health of solver.csv.
#pragma once

#include <chrono>
#include <iosfwd>
#include <memory>
#include <optional>
#include <string>

#include "viscompm/boundary/colliders.hpp"
#include "viscompm/io/frame_writer.hpp"
#include "viscompm/io/solver_log.hpp"
#include "viscompm/linalg/linear_solver.hpp"
#include "viscompm/materials/material.hpp"
#include "viscompm/scene/scene.hpp"
#include "viscompm/simulation/run_setup.hpp"
#include "viscompm/simulation/stepping.hpp"
#include "viscompm/simulation/time_integrator.hpp"

namespace viscompm::simulation {

/// What the ranks of a run agree on after every step (Simulation::run), in one collective: a
/// signal may reach only some ranks, their clocks differ, and only rank 0 writes solver.csv.
struct RunControl {
  int stop_signal = 0;             ///< the signal of a stop request (stop_request.hpp); 0: none
  bool checkpoint_due = false;     ///< Output/Checkpoint wall seconds have passed since the last one
  bool solver_log_failed = false;  ///< solver.csv could not be written
  bool stop() const { return stop_signal != 0; }
  /// The ranks' states combined (collective): the largest signal, a checkpoint due or a failed
  /// log on any rank.
  static RunControl agreed(const RunControl& local, const parallel::Communicator& comm);
};

class Simulation {
 public:
  /// A run of `scene`; with `restart_file`, the state comes from that checkpoint instead of the
  /// scene's bodies (InputError if it does not fit the scene).
  Simulation(const scene::SceneConfig& scene, const linalg::SolverConfiguration& solver,
             const parallel::Communicator& comm, const std::optional<std::string>& restart_file = std::nullopt);
  /// The same with the materials built by the caller, one per scene material in the scene's
  /// order (models defined outside the registry: a library user's, or a test's).
  Simulation(const scene::SceneConfig& scene, materials::MaterialList materials,
             const linalg::SolverConfiguration& solver, const parallel::Communicator& comm,
             const std::optional<std::string>& restart_file = std::nullopt);
  // The stepping holds references to the scene, state and boundary held here.
  Simulation(const Simulation&) = delete;
  Simulation& operator=(const Simulation&) = delete;

  /// Writes frame 0 (unless restarted), then every remaining frame of the scene, with checkpoints
  /// as the scene asks, logging progress to `log` on rank 0. After every step the ranks agree on
  /// a stop request (SIGTERM, SIGINT): the run then writes a checkpoint and returns with
  /// RunSummary::stop_signal set. A failed write (disk full, directory gone) is SimulationError;
  /// every file written before stays intact.
  RunSummary run(std::ostream& log);
  /// Writes DIR/checkpoint_NNNNN.h5 for the current frame; returns its path. The run then
  /// continues as one restarted from it would (TimeIntegrator::reset_reuse).
  std::string write_checkpoint();
  /// Advances to time t_end with adaptive steps (no output, no stop requests). Throws
  /// SimulationError if a step fails at the smallest Δt. False if a step was interrupted
  /// (an interrupt installed on integrator()): the state is that after the last step taken.
  bool advance_to(double t_end, RunSummary& summary, std::ostream* log = nullptr) {
    return stepper_.advance_to(t_end, summary, log);
  }

  double time() const { return state_.time; }
  /// The Δt the next step would try (the particle CFL within the scene's bounds).
  double suggested_time_step() const { return stepper_.suggested_time_step(); }
  std::int64_t step_count() const { return state_.step; }
  particles::ParticleSet& particles() { return state_.particles; }
  const materials::MaterialList& materials() const { return materials_; }
  TimeIntegrator& integrator() { return stepper_.integrator(); }
  const grid::GridGeometry& grid() const { return geometry_; }
  const boundary::Boundary& boundary() const { return boundary_; }
  const std::vector<particles::Emitter>& emitters() const { return state_.emitters; }
  /// Mass delivered by all emitters so far.
  double emitted_mass() const { return state_.emitted_mass(); }
  /// What a frame written now holds besides the particles (collider surfaces, emitted mass).
  io::FrameExtras frame_extras() const;
  /// Writes DIR/surface_NNNNN.{obj,vdb}: the particles' surface (Output/Surface voxel size).
  void write_surface(int frame) const;
  /// How run() writes a frame's particle file: in pieces (io::WritePieces), between which the
  /// ranks agree on a stop request (this rank's signal, stop_request.hpp). A request agreed there
  /// removes the partial frame file and stops the run as after a step (checkpoint, RunSummary's
  /// stop_signal; the frame is written by the restart) — or, for frame 0, throws StopRequested
  /// (nothing simulated). Tests make the pieces small and wrap `stop`.
  io::WritePieces& frame_pieces() { return frame_pieces_; }

 private:
  scene::SceneConfig scene_;
  parallel::Communicator comm_;
  grid::GridGeometry geometry_;
  materials::MaterialList materials_;
  boundary::Boundary boundary_;
  SimulationState state_;
  Stepper stepper_;
  std::unique_ptr<io::SolverLog> solver_log_;  ///< open during run()
  std::vector<io::FrameInfo> frames_;
  std::chrono::steady_clock::time_point last_checkpoint_time_;
  std::optional<std::string> wall_checkpoint_;  ///< the last checkpoint written between frames by this run
  io::WritePieces frame_pieces_;                ///< how frames are written (stop: this rank's signal)

  /// This rank's view of the run's control state now (its own signal, clock and log).
  RunControl local_control() const;
  /// After a step inside run(): agrees on the RunControl, writes the checkpoint it asks for;
  /// true if the run must stop (its checkpoint written).
  bool stop_requested(RunSummary& summary, std::ostream* log);
  /// Writes DIR/checkpoint_step_SSSSSSSS.h5 (the steps taken) and removes the one this run wrote
  /// between frames before; wall_checkpoint_ names it.
  void write_wall_checkpoint();
  /// Writes DIR/NAME and resets the integrator's reuse, as write_checkpoint.
  std::string write_checkpoint_file(const std::string& name);
  void write_frame(int frame);
  /// Creates the output directory and opens solver.csv (appended to when restarted).
  void open_output();
  /// The first line of the log: particles, grid, ranks, frames, emitters.
  void log_start(std::ostream& log) const;
};

}  // namespace viscompm::simulation
