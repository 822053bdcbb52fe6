#include "viscompm/simulation/simulation.hpp"

#include <Teuchos_TimeMonitor.hpp>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <numeric>
#include <iomanip>
#include <ostream>

#include "viscompm/core/error.hpp"
#include "viscompm/io/checkpoint.hpp"
#include "viscompm/io/particle_file.hpp"
#include "viscompm/materials/registry.hpp"
#include "viscompm/parallel/migration.hpp"
#include "viscompm/linalg/rcb_partition.hpp"
#include "viscompm/particles/sampling.hpp"

namespace viscompm::simulation {

grid::GridGeometry make_grid(const scene::GridSettings& g) {
  grid::GridGeometry geometry;
  geometry.origin = g.lower_corner;
  geometry.dx = g.cell_size;
  for (int d = 0; d < 3; ++d)
    geometry.cells[d] = static_cast<int>(std::ceil((g.upper_corner[d] - g.lower_corner[d]) / g.cell_size - 1e-9));
  return geometry;
}

materials::MaterialList make_materials(const scene::SceneConfig& scene) {
  materials::MaterialList list;
  for (const auto& m : scene.materials) list.push_back(materials::find_model(m.model)->create(m.name, m.values));
  return list;
}

boundary::Boundary make_boundary(const scene::SceneConfig& scene) {
  std::vector<boundary::Collider> colliders;
  for (const auto& c : scene.colliders) {
    boundary::Collider collider;
    collider.name = c.name;
    collider.shape = scene::shape_of(c);
    collider.type = boundary::contact_type_from_name(c.contact);
    collider.velocity = c.velocity;
    collider.start_time = c.start_time;
    collider.stop_time = c.stop_time;
    colliders.push_back(collider);
  }
  boundary::DomainWalls walls;
  walls.type = boundary::contact_type_from_name(scene.grid.walls);
  walls.thickness = scene.grid.wall_thickness;
  return boundary::Boundary(std::move(colliders), walls);
}

particles::ParticleSet sample_particles(const scene::SceneConfig& scene, const grid::GridGeometry& grid,
                                        grid::KernelOrder order, const parallel::Decomposition& decomposition,
                                        const materials::MaterialList& materials, int rank) {
  particles::ParticleSet set;
  ParticleId id_offset = 0;
  for (const auto& body : scene.bodies) {
    particles::BodySampling sampling;
    sampling.shape = scene::shape_of(body);
    sampling.particles_per_cell = body.particles_per_cell;
    sampling.velocity = body.velocity;
    sampling.angular_velocity = body.angular_velocity;
    for (std::size_t m = 0; m < materials.size(); ++m)
      if (materials[m]->name() == body.material) sampling.material_id = static_cast<int>(m);
    sampling.density = materials[sampling.material_id]->density();
    particles::sample_body(sampling, grid, id_offset,
                           [&](const Vec3& x) { return parallel::particle_owner(decomposition, grid, order, x) == rank; },
                           set);
    id_offset += particles::lattice_size(sampling, grid);
  }
  return set;
}

Simulation::Simulation(const scene::SceneConfig& scene, const linalg::SolverConfiguration& solver,
                       const parallel::Communicator& comm, const std::string& restart_file)
    : scene_(scene),
      comm_(comm),
      geometry_(make_grid(scene.grid)),
      order_(grid::kernel_order_from_name(scene.simulation.kernel)),
      decomposition_(std::make_unique<parallel::BlockDecomposition>(geometry_, comm.size())),
      materials_(make_materials(scene)),
      boundary_(make_boundary(scene)),
      time_step_cap_(scene.simulation.max_time_step) {
  if (restart_file.empty()) {
    particles_ = sample_particles(scene, geometry_, order_, *decomposition_, materials_, comm.rank());
  } else {
    io::RunState state;
    std::string names;
    particles_ = io::read_checkpoint(restart_file, comm_, state, names);
    if (names != io::material_names(materials_))
      throw InputError(restart_file + ": its materials (" + names + ") are not the scene's (" +
                       io::material_names(materials_) + ")");
    time_ = state.time;
    step_ = state.step;
    frame_ = state.frame;
    time_step_cap_ = state.time_step_cap;
    restarted_ = true;
    // The same rank count continues with the same ownership (bit-for-bit restarts).
    if (state.decomposition_boxes.size() == 6u * static_cast<std::size_t>(comm_.size())) {
      std::vector<parallel::BoxDecomposition::Box> boxes(comm_.size());
      for (int r = 0; r < comm_.size(); ++r) {
        const double* b = state.decomposition_boxes.data() + 6 * r;
        boxes[r] = {Vec3(b[0], b[1], b[2]), Vec3(b[3], b[4], b[5])};
      }
      decomposition_ = std::make_unique<parallel::BoxDecomposition>(geometry_, std::move(boxes));
    }
    parallel::migrate_particles(comm_, *decomposition_, geometry_, order_, particles_);
  }
  if (comm_.sum(static_cast<std::int64_t>(particles_.size())) == 0)
    throw InputError(scene.file + ": parameter 'Bodies': no particle falls inside the grid");
  boundary_.clamp_particles(geometry_, particles_.position);
  IntegratorSettings settings;
  settings.gravity = scene.simulation.gravity;
  settings.transfer.scheme = transfer::scheme_from_name(scene.simulation.transfer);
  settings.transfer.flip_ratio = scene.simulation.flip_ratio;
  settings.newton = scene.newton;
  settings.delete_outside_particles = scene.grid.outside_particles == "delete";
  integrator_ = std::make_unique<TimeIntegrator>(comm_, geometry_, order_, *decomposition_, settings, materials_,
                                                 boundary_, solver);
}

double Simulation::suggested_time_step() const {
  double speed = 0.0;
  for (const Vec3& v : particles_.velocity) speed = std::max(speed, v.norm());
  for (const auto& c : boundary_.colliders()) speed = std::max(speed, c.velocity_at(time_).norm());
  speed = comm_.max(speed);
  double dt = std::min(time_step_cap_, scene_.simulation.max_time_step);
  if (speed > 0.0) dt = std::min(dt, scene_.simulation.cfl * geometry_.dx / speed);
  return dt;
}

void Simulation::rebalance_if_needed(RunSummary& summary, std::ostream* log) {
  const double threshold = scene_.grid.rebalance_threshold;
  if (threshold <= 0.0 || comm_.size() == 1) return;
  const double before = parallel::imbalance(comm_, particles_.size());
  // Re-partition when the threshold is crossed, but not again while the imbalance stays at what
  // the last re-partition could reach (cells are indivisible).
  if (before <= std::max(threshold, 1.05 * balanced_imbalance_)) return;
  auto candidate = linalg::make_rcb_decomposition(comm_, geometry_, particles_);
  // Keep the new partition only if it balances better (cells are indivisible: on coarse grids
  // the bisection's cut may land where it cannot help).
  std::vector<double> counts(comm_.size(), 0.0);
  for (const Vec3& x : particles_.position) counts[parallel::particle_owner(*candidate, geometry_, order_, x)] += 1.0;
  MPI_Allreduce(MPI_IN_PLACE, counts.data(), comm_.size(), MPI_DOUBLE, MPI_SUM, comm_.comm());
  const double total = std::accumulate(counts.begin(), counts.end(), 0.0);
  const double predicted = *std::max_element(counts.begin(), counts.end()) / (total / comm_.size());
  if (predicted >= before) {
    balanced_imbalance_ = before;
    return;
  }
  decomposition_ = std::move(candidate);
  integrator_->set_decomposition(*decomposition_);
  parallel::migrate_particles(comm_, *decomposition_, geometry_, order_, particles_);
  ++summary.rebalances;
  const double after = parallel::imbalance(comm_, particles_.size());
  balanced_imbalance_ = after;
  if (log && comm_.is_root())
    *log << "  step " << step_ + 1 << ": rebalanced (" << decomposition_->describe() << "), particle imbalance "
         << before << " -> " << after << "\n";
}

void Simulation::advance_to(double t_end, RunSummary& summary, std::ostream* log) {
  const double min_dt = scene_.simulation.min_time_step;
  while (time_ < t_end * (1.0 - 1e-14)) {
    rebalance_if_needed(summary, log);
    double dt = suggested_time_step();
    const double remaining = t_end - time_;
    if (dt >= remaining * (1.0 - 1e-9)) dt = remaining;
    else if (dt > 0.5 * remaining) dt = 0.5 * remaining;  // no sliver step before the frame
    std::string dump_prefix;
    for (double s : scene_.output.matrix_market_steps)
      if (static_cast<std::int64_t>(s) == step_ + 1)
        dump_prefix = scene_.output.directory + "/newton_step_" + std::to_string(step_ + 1);
    for (;;) {
      const StepReport report = integrator_->step(particles_, time_, dt, dump_prefix);
      const auto& newton = report.newton;
      for (std::size_t k = 0; k < newton.linear_solves.size(); ++k) {
        if (solver_log_) solver_log_->record(step_ + 1, static_cast<int>(k + 1), newton.linear_solves[k]);
        summary.linear_iterations += newton.linear_solves[k].iterations;
      }
      summary.newton_iterations += newton.iterations;
      if (newton.converged) {
        summary.particles_deleted += comm_.sum(static_cast<std::int64_t>(report.particles_deleted));
        summary.particles_migrated += comm_.sum(static_cast<std::int64_t>(report.particles_sent));
        summary.shared_node_steps += comm_.sum(static_cast<std::int64_t>(report.shared_nodes));
        summary.owned_node_steps += comm_.sum(static_cast<std::int64_t>(report.owned_nodes));
        break;
      }
      ++summary.retries;
      if (dt * 0.5 < min_dt)
        throw SimulationError("Newton failed at t = " + std::to_string(time_) + " with the smallest Δt (" +
                              newton.failure + ")");
      if (log && comm_.is_root() && ++retries_reported_ <= 10)
        *log << "  step " << step_ + 1 << ": Newton failed (" << newton.failure << ") at Δt = " << dt
             << ", retrying with Δt/2 [" << newton.history() << "]"
             << (retries_reported_ == 10 ? " (further retries are counted, not shown)" : "") << "\n";
      dt *= 0.5;
      time_step_cap_ = dt;
    }
    time_ += dt;
    ++step_;
    ++summary.steps;
    time_step_cap_ = std::min(1.5 * time_step_cap_, scene_.simulation.max_time_step);
  }
  time_ = t_end;
}

namespace {
std::string clock_text(double seconds) {
  const long s = std::lround(std::max(seconds, 0.0));
  std::ostringstream out;
  out << s / 60 << ":" << std::setw(2) << std::setfill('0') << s % 60;
  return out.str();
}
}  // namespace

std::string Simulation::write_checkpoint() const {
  io::RunState state{time_, step_, frame_, time_step_cap_, scene_.name, {}};
  if (const auto* boxes = dynamic_cast<const parallel::BoxDecomposition*>(decomposition_.get()))
    for (const auto& b : boxes->boxes())
      state.decomposition_boxes.insert(state.decomposition_boxes.end(),
                                       {b.lower.x(), b.lower.y(), b.lower.z(), b.upper.x(), b.upper.y(), b.upper.z()});
  return io::write_checkpoint(scene_.output.directory, state, particles_, materials_, comm_);
}

namespace {
// The frames a restarted run inherits: their times and sizes, read from the files (rank 0).
std::vector<io::FrameInfo> existing_frames(const std::string& directory, int last) {
  std::vector<io::FrameInfo> frames;
  for (int f = 0; f <= last; ++f) {
    const std::string path = (std::filesystem::path(directory) / io::frame_file_name(f)).string();
    if (!std::filesystem::exists(path)) continue;
    std::int64_t count = 0;
    io::FileAttributes attributes = io::read_file_attributes(path, count);
    frames.push_back({f, attributes.reals["time"], attributes.integers["step"], count});
  }
  return frames;
}
}  // namespace

RunSummary Simulation::run(std::ostream& log) {
  const std::string& directory = scene_.output.directory;
  if (comm_.is_root()) {
    std::error_code error;
    std::filesystem::create_directories(directory, error);
    if (error || !std::filesystem::is_directory(directory))
      throw InputError(scene_.file + ": parameter 'Output/Directory': cannot create '" + directory + "'");
  }
  comm_.barrier();
  solver_log_ = std::make_unique<io::SolverLog>(directory, comm_.is_root(), comm_.size(), restarted_);

  RunSummary summary;
  const auto start = std::chrono::steady_clock::now();
  const int checkpoint_every = scene_.output.checkpoint_every;
  auto write = [&](int frame) {
    frame_ = frame;
    frames_.push_back(io::write_frame(directory, {frame, time_, step_, 0}, particles_, materials_, comm_));
    if (comm_.is_root()) io::write_xdmf(directory, frames_);
    if (checkpoint_every > 0 && frame % checkpoint_every == 0) write_checkpoint();
  };
  if (restarted_) {
    if (comm_.is_root()) frames_ = existing_frames(directory, frame_);  // for the XDMF index
  } else {
    write(0);
  }
  const int frames = scene_.simulation.frames;
  const double frame_duration = 1.0 / scene_.simulation.frame_rate;
  const std::int64_t particle_count = comm_.sum(static_cast<std::int64_t>(particles_.size()));
  if (comm_.is_root())
    log << scene_.name << ": " << particle_count << " particles, grid " << geometry_.cells.transpose() << " cells of "
        << geometry_.dx << " m, " << comm_.size() << " rank(s), " << frames << " frames"
        << (restarted_ ? ", restarted at frame " + std::to_string(frame_) : std::string()) << "\n";
  const int first = frame_ + 1;
  for (int frame = first; frame <= frames; ++frame) {
    advance_to(frame * frame_duration, summary, &log);
    write(frame);
    const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const int done = frame - first + 1;
    if (comm_.is_root())
      log << "frame " << std::setw(4) << frame << "/" << frames << "  t = " << std::setprecision(4) << std::fixed
          << time_ << " s  steps " << summary.steps << "  newton " << summary.newton_iterations << "  cg "
          << summary.linear_iterations << "  retries " << summary.retries << "  wall " << clock_text(elapsed)
          << "  eta " << clock_text(elapsed / done * (frames - frame)) << std::defaultfloat << std::endl;
  }
  summary.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  solver_log_.reset();
  return summary;
}

}  // namespace viscompm::simulation
