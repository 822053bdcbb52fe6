#include "viscompm/simulation/simulation.hpp"

#include <chrono>
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <ostream>
#include <sstream>

#include "viscompm/core/error.hpp"
#include "viscompm/geometry/level_set.hpp"
#include "viscompm/io/checkpoint.hpp"
#include "viscompm/io/collider_output.hpp"
#include "viscompm/io/particle_file.hpp"
#include "viscompm/core/stop_request.hpp"

namespace viscompm::simulation {

namespace {
// A scene built in code names its materials and bodies; the run needs them as indices.
scene::SceneConfig linked(const scene::SceneConfig& scene) {
  scene::SceneConfig copy = scene;
  scene::link_names(copy);
  return copy;
}

materials::MaterialList one_per_scene_material(materials::MaterialList materials, const scene::SceneConfig& scene) {
  if (materials.size() != scene.materials.size())
    throw std::invalid_argument("Simulation: one material per scene material expected");
  return materials;
}
}  // namespace

Simulation::Simulation(const scene::SceneConfig& scene, const linalg::SolverConfiguration& solver,
                       const parallel::Communicator& comm, const std::optional<std::string>& restart_file)
    : Simulation(scene, make_materials(scene), solver, comm, restart_file) {}

Simulation::Simulation(const scene::SceneConfig& scene, materials::MaterialList materials,
                       const linalg::SolverConfiguration& solver, const parallel::Communicator& comm,
                       const std::optional<std::string>& restart_file)
    : scene_(linked(scene)),
      comm_(comm),
      geometry_(make_grid(scene_.grid)),
      materials_(one_per_scene_material(std::move(materials), scene_)),
      boundary_(make_boundary(scene_)),
      state_(initial_state(scene_, geometry_, scene_.simulation.kernel, materials_, boundary_, comm_, restart_file)),
      stepper_(scene_, state_, geometry_, scene_.simulation.kernel, materials_, boundary_, solver, comm_) {
  frame_pieces_.stop = [] { return stop_signal(); };
}

RunControl RunControl::agreed(const RunControl& local, const parallel::Communicator& comm) {
  const std::vector<std::int64_t> all = comm.max(std::vector<std::int64_t>{
      local.stop_signal, local.checkpoint_due ? 1 : 0, local.solver_log_failed ? 1 : 0});
  RunControl agreed;
  agreed.stop_signal = static_cast<int>(all[0]);
  agreed.checkpoint_due = all[1] != 0;
  agreed.solver_log_failed = all[2] != 0;
  return agreed;
}

RunControl Simulation::local_control() const {
  RunControl local;
  local.stop_signal = stop_signal();
  const double wall = scene_.output.checkpoint_wall_seconds;
  local.checkpoint_due =
      wall > 0.0 && std::chrono::duration<double>(std::chrono::steady_clock::now() - last_checkpoint_time_).count() >= wall;
  local.solver_log_failed = solver_log_ && !solver_log_->good();
  return local;
}

bool Simulation::stop_requested(RunSummary& summary, std::ostream* log) {
  const RunControl control = RunControl::agreed(local_control(), comm_);
  if (control.solver_log_failed)
    throw SimulationError("cannot write " + solver_log_->path() + ": " + io::write_failure_reason(solver_log_->path()));
  if (!control.stop() && !control.checkpoint_due) return false;
  write_wall_checkpoint();
  if (!control.stop()) {
    if (log && comm_.is_root()) *log << "  step " << state_.step << ": checkpoint " << *wall_checkpoint_ << "\n";
    return false;
  }
  summary.stop_signal = control.stop_signal;
  summary.stop_checkpoint = *wall_checkpoint_;
  return true;
}

void Simulation::write_wall_checkpoint() {
  // A checkpoint between frames, replacing the one this run wrote before.
  const std::optional<std::string> previous = wall_checkpoint_;
  wall_checkpoint_ = write_checkpoint_file(io::step_checkpoint_file_name(state_.step));
  last_checkpoint_time_ = std::chrono::steady_clock::now();
  if (comm_.is_root() && previous && *previous != *wall_checkpoint_) {
    std::error_code ignored;
    std::filesystem::remove(*previous, ignored);
  }
}

std::string Simulation::write_checkpoint() { return write_checkpoint_file(io::checkpoint_file_name(state_.frame)); }

std::string Simulation::write_checkpoint_file(const std::string& name) {
  integrator().reset_reuse();  // continue as a run restarted from this checkpoint starts
  const std::string path = (std::filesystem::path(scene_.output.directory) / name).string();
  io::write_checkpoint(path, state_.record(scene_.name), state_.particles, materials_, comm_);
  return path;
}

void Simulation::write_frame(int frame) {
  const int previous = state_.frame;
  state_.frame = frame;
  try {
    frames_.push_back(io::write_frame(scene_.output.directory, {frame, state_.time, state_.step, 0}, state_.particles,
                                      materials_, comm_, frame_extras(), frame_pieces_));
  } catch (const StopRequested&) {
    state_.frame = previous;  // not written (its partial file removed): a restart writes it
    throw;
  }
  // Rank 0 writes the index; every rank learns whether it could.
  std::string failure;
  if (comm_.is_root()) {
    try {
      io::write_xdmf(scene_.output.directory, frames_);
    } catch (const SimulationError& e) {
      failure = e.what();
    }
  }
  if (comm_.any(!failure.empty())) throw SimulationError(failure.empty() ? "rank 0 could not write particles.xdmf" : failure);
  if (scene_.output.surface_voxel_size > 0.0) write_surface(frame);
  const int every = scene_.output.checkpoint_every;
  if (every > 0 && frame % every == 0) write_checkpoint();
}

namespace {
std::string clock_text(double seconds) {
  const long s = std::lround(std::max(seconds, 0.0));
  std::ostringstream out;
  out << s / 60 << ":" << std::setw(2) << std::setfill('0') << s % 60;
  return out.str();
}

// The frames a restarted run inherits: their times and sizes, read from the files (rank 0).
std::vector<io::FrameInfo> existing_frames(const std::string& directory, int last) {
  std::vector<io::FrameInfo> frames;
  for (int f = 0; f <= last; ++f) {
    const std::string path = (std::filesystem::path(directory) / io::frame_file_name(f)).string();
    if (!std::filesystem::exists(path)) continue;
    std::int64_t count = 0;
    io::FileAttributes attributes = io::read_file_attributes(path, count);
    frames.push_back({f, attributes.reals["time"], attributes.integers["step"], count,
                      attributes.integers["collider_vertex_count"], attributes.integers["collider_triangle_count"]});
  }
  return frames;
}
}  // namespace

void Simulation::open_output() {
  const std::string& directory = scene_.output.directory;
  std::error_code error;
  if (comm_.is_root()) std::filesystem::create_directories(directory, error);
  if (comm_.any(comm_.is_root() && (error || !std::filesystem::is_directory(directory))))
    throw parameter_error(scene_.file, "Output/Directory", "cannot create '" + directory + "'");
  solver_log_ = std::make_unique<io::SolverLog>(directory, comm_.is_root(), comm_.size(), state_.restarted);
  if (comm_.any(!solver_log_->good()))
    throw SimulationError("cannot write " + solver_log_->path() + ": " + io::write_failure_reason(solver_log_->path()));
  if (state_.restarted && comm_.is_root()) frames_ = existing_frames(directory, state_.frame);  // for the XDMF index
}

void Simulation::log_start(std::ostream& log) const {
  const std::int64_t particle_count = comm_.sum(static_cast<std::int64_t>(state_.particles.size()));
  if (!comm_.is_root()) return;
  log << scene_.name << ": " << particle_count << " particles, grid " << geometry_.cells.transpose() << " cells of "
      << geometry_.dx << " m, " << comm_.size() << " rank(s), " << scene_.simulation.frames << " frames"
      << (state_.restarted
              ? ", restarted at t = " + std::to_string(state_.time) + " (frame " + std::to_string(state_.frame) + ")"
              : std::string())
      << "\n";
  for (const auto& e : state_.emitters)
    log << "  emitter " << e.spec().name << ": " << e.layer_size() << " particles per layer, "
        << e.layer_size() / e.layer_interval() << " particles/s, "
        << e.particle_mass() * e.layer_size() / e.layer_interval() << " kg/s\n";
}

RunSummary Simulation::run(std::ostream& log) {
  open_output();
  RunSummary summary;
  const auto start = std::chrono::steady_clock::now();
  last_checkpoint_time_ = start;
  // Stop requests: a signal abandons the current step at its next Newton iteration, and after
  // every step the ranks agree on it (and on wall-clock checkpoints, and solver.csv's health).
  integrator().set_interrupt([] { return stop_signal() != 0; });
  struct Leave {  // however run() ends, the integrator ignores stop requests again
    TimeIntegrator& integrator;
    ~Leave() { integrator.set_interrupt({}); }
  } leave{integrator()};
  stepper_.set_solver_log(solver_log_.get());
  const AfterStep after_step = [&] { return stop_requested(summary, &log); };
  // A stop request while frame 0 is written (between its pieces) ends the run as one during its
  // set-up does: StopRequested, nothing simulated, nothing to continue from.
  if (!state_.restarted) write_frame(0);
  log_start(log);
  const int frames = scene_.simulation.frames;
  const double frame_duration = 1.0 / scene_.simulation.frame_rate;
  const int first = state_.frame + 1;
  for (int frame = first; frame <= frames; ++frame) {
    if (!stepper_.advance_to(frame * frame_duration, summary, &log, after_step)) break;
    try {
      write_frame(frame);
    } catch (const StopRequested& e) {
      // Agreed by every rank between two pieces of the frame's file, which is removed: the run
      // stops as after a step, with a checkpoint from which a restart writes this frame.
      write_wall_checkpoint();
      summary.stop_signal = e.signal;
      summary.stop_checkpoint = *wall_checkpoint_;
      break;
    }
    if (after_step()) break;  // a stop request that came while the frame was written
    const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const int done = frame - first + 1;
    if (comm_.is_root())
      log << "frame " << std::setw(4) << frame << "/" << frames << "  t = " << std::setprecision(4) << std::fixed
          << state_.time << " s  steps " << summary.steps << "  newton " << summary.newton_iterations << "  cg "
          << summary.linear_iterations << "  graphs " << summary.graph_builds << "  retries " << summary.retries
          << "  wall " << clock_text(elapsed) << "  eta " << clock_text(elapsed / done * (frames - frame))
          << std::defaultfloat << std::endl;
  }
  summary.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  stepper_.set_solver_log(nullptr);
  solver_log_.reset();
  return summary;
}

io::FrameExtras Simulation::frame_extras() const {
  io::FrameExtras extras;
  io::add_collider_surfaces(boundary_, state_.time, geometry_.origin, geometry_.upper_corner(), extras);
  extras.emitted_mass = state_.emitted_mass();
  return extras;
}

void Simulation::write_surface(int frame) const {
  // The particles of all ranks on rank 0, as spheres of the particle spacing (h = V0^(1/3)).
  const auto& particles = state_.particles;
  std::vector<double> local;
  double spacing = 0.0;
  for (std::size_t p = 0; p < particles.size(); ++p) {
    local.insert(local.end(), particles.position[p].data(), particles.position[p].data() + 3);
    spacing = std::max(spacing, std::cbrt(particles.volume0[p]));
  }
  const std::vector<double> all = comm_.all_gather(local);
  spacing = comm_.max(spacing);
  if (!comm_.is_root() || all.empty()) return;
  std::vector<Vec3> positions(all.size() / 3);
  for (std::size_t p = 0; p < positions.size(); ++p) positions[p] = Vec3(all[3 * p], all[3 * p + 1], all[3 * p + 2]);
  std::ostringstream name;
  name << scene_.output.directory << "/surface_" << std::setw(5) << std::setfill('0') << frame;
  try {
    const geometry::TriangleMesh surface =
        geometry::particle_surface(positions, spacing, scene_.output.surface_voxel_size, name.str() + ".vdb");
    geometry::write_obj(surface, name.str() + ".obj");
  } catch (const StopRequested&) {
    // A stop request while the surface was built: the frame stays without it, and the run stops
    // after the frame (run()).
  }
}

}  // namespace viscompm::simulation
