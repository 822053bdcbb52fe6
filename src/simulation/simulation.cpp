#include "viscompm/simulation/simulation.hpp"

#include <Teuchos_TimeMonitor.hpp>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <ostream>

#include "viscompm/core/error.hpp"
#include "viscompm/materials/registry.hpp"
#include "viscompm/parallel/migration.hpp"
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
                                        grid::KernelOrder order, const parallel::BlockDecomposition& decomposition,
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
                       const parallel::Communicator& comm)
    : scene_(scene),
      comm_(comm),
      geometry_(make_grid(scene.grid)),
      order_(grid::kernel_order_from_name(scene.simulation.kernel)),
      decomposition_(geometry_, comm.size()),
      materials_(make_materials(scene)),
      boundary_(make_boundary(scene)),
      time_step_cap_(scene.simulation.max_time_step) {
  particles_ = sample_particles(scene, geometry_, order_, decomposition_, materials_, comm.rank());
  if (comm_.sum(static_cast<std::int64_t>(particles_.size())) == 0)
    throw InputError(scene.file + ": parameter 'Bodies': no particle falls inside the grid");
  boundary_.clamp_particles(geometry_, particles_.position);
  IntegratorSettings settings;
  settings.gravity = scene.simulation.gravity;
  settings.transfer.scheme = transfer::scheme_from_name(scene.simulation.transfer);
  settings.transfer.flip_ratio = scene.simulation.flip_ratio;
  settings.newton = scene.newton;
  integrator_ = std::make_unique<TimeIntegrator>(comm_, geometry_, order_, decomposition_, settings, materials_,
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

void Simulation::advance_to(double t_end, RunSummary& summary, std::ostream* log) {
  const double min_dt = scene_.simulation.min_time_step;
  while (time_ < t_end * (1.0 - 1e-14)) {
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
      if (newton.converged) break;
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

RunSummary Simulation::run(std::ostream& log) {
  const std::string& directory = scene_.output.directory;
  if (comm_.is_root()) {
    std::error_code error;
    std::filesystem::create_directories(directory, error);
    if (error || !std::filesystem::is_directory(directory))
      throw InputError(scene_.file + ": parameter 'Output/Directory': cannot create '" + directory + "'");
  }
  comm_.barrier();
  solver_log_ = std::make_unique<io::SolverLog>(directory, comm_.is_root(), comm_.size());

  RunSummary summary;
  const auto start = std::chrono::steady_clock::now();
  auto write = [&](int frame) {
    frames_.push_back(io::write_frame(directory, {frame, time_, step_, 0}, particles_, materials_, comm_));
    if (comm_.is_root()) io::write_xdmf(directory, frames_);
  };
  write(0);
  const int frames = scene_.simulation.frames;
  const double frame_duration = 1.0 / scene_.simulation.frame_rate;
  const std::int64_t particle_count = comm_.sum(static_cast<std::int64_t>(particles_.size()));
  if (comm_.is_root())
    log << scene_.name << ": " << particle_count << " particles, grid " << geometry_.cells.transpose() << " cells of "
        << geometry_.dx << " m, " << comm_.size() << " rank(s), " << frames << " frames\n";
  for (int frame = 1; frame <= frames; ++frame) {
    advance_to(frame * frame_duration, summary, &log);
    write(frame);
    const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (comm_.is_root())
      log << "frame " << std::setw(4) << frame << "/" << frames << "  t = " << std::setprecision(4) << std::fixed
          << time_ << " s  steps " << summary.steps << "  newton " << summary.newton_iterations << "  cg "
          << summary.linear_iterations << "  retries " << summary.retries << "  wall " << clock_text(elapsed) << "  eta "
          << clock_text(elapsed / frame * (frames - frame)) << std::defaultfloat << std::endl;
  }
  summary.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  solver_log_.reset();
  return summary;
}

}  // namespace viscompm::simulation
