#include "viscompm/simulation/simulation.hpp"

#include <unistd.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <numeric>
#include <ostream>
#include <sstream>
#include <type_traits>

#include "viscompm/core/error.hpp"
#include "viscompm/io/checkpoint.hpp"
#include "viscompm/geometry/level_set.hpp"
#include "viscompm/io/collider_output.hpp"
#include "viscompm/io/particle_file.hpp"
#include "viscompm/linalg/rcb_partition.hpp"
#include "viscompm/materials/registry.hpp"
#include "viscompm/parallel/migration.hpp"
#include "viscompm/particles/sampling.hpp"
#include "viscompm/simulation/scene_objects.hpp"
#include "viscompm/simulation/stop_request.hpp"

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
/// Memory per particle: the default scene's peak memory grows by 3.2 KiB per particle with the
/// assembled Hessian and Jacobi (doc/contracts.md; MueLu needs more).
constexpr double bytes_per_particle = 4096.0;

// The memory this rank may use: the machine's, shared among its ranks, or the control group's
// limit (batch systems) if lower.
double memory_of_this_rank(const parallel::Communicator& comm) {
  double bytes = static_cast<double>(sysconf(_SC_PHYS_PAGES)) * static_cast<double>(sysconf(_SC_PAGESIZE));
  for (const char* limit_file : {"/sys/fs/cgroup/memory.max", "/sys/fs/cgroup/memory/memory.limit_in_bytes"}) {
    std::ifstream in(limit_file);
    double limit = 0.0;
    if (in >> limit && limit > 0.0) bytes = std::min(bytes, limit);
  }
  MPI_Comm node;
  MPI_Comm_split_type(comm.comm(), MPI_COMM_TYPE_SHARED, comm.rank(), MPI_INFO_NULL, &node);
  int ranks_here = 1;
  MPI_Comm_size(node, &ranks_here);
  MPI_Comm_free(&node);
  return bytes / ranks_here;
}
}  // namespace

void check_memory(const scene::SceneConfig& scene, const parallel::Communicator& comm) {
  // Particles: the lattice sites of each body's bounding box inside the grid (what sampling
  // visits), times the shape's share of its box. In doubles: nothing overflows.
  const Vec3 lower = scene.grid.lower_corner, upper = scene.grid.upper_corner;
  double particles = 0.0;
  for (const auto& body : scene.bodies) {
    const Shape shape = scene::shape_of(body);
    Vec3 lo, hi;
    shape.bounding_box(lo, hi);
    const double h = scene.grid.cell_size / body.particles_per_cell;
    double sites = 1.0;
    for (int d = 0; d < 3; ++d) sites *= std::max(0.0, std::min(hi[d], upper[d]) - std::max(lo[d], lower[d])) / h;
    const double share = shape.kind == Shape::Kind::sphere ? M_PI / 6.0 : shape.kind == Shape::Kind::cylinder ? M_PI / 4.0 : 1.0;
    particles += sites * share;
  }
  const double needed = particles * bytes_per_particle;
  const double available = comm.sum(memory_of_this_rank(comm));
  if (needed <= available) return;
  std::ostringstream reason;
  reason << std::setprecision(3) << scene.file << ": parameter 'Grid/Cell size': " << scene.grid.cell_size
         << " m gives about " << particles << " particles, an estimated " << needed / 1073741824.0
         << " GiB (" << bytes_per_particle / 1024.0 << " KiB per particle), more than the " << available / 1073741824.0
         << " GiB of memory of " << comm.size() << " rank(s)";
  throw InputError(reason.str());
}

materials::MaterialList make_materials(const scene::SceneConfig& scene) {
  materials::MaterialList list;
  for (const auto& m : scene.materials) list.push_back(materials::find_model(m.model)->create(m.name, m.values));
  return list;
}

namespace {
// The grid a scene asks for: cells of the given size covering [lower, upper] (rounded up).
grid::GridGeometry make_grid(const scene::GridSettings& g) {
  grid::GridGeometry geometry;
  geometry.origin = g.lower_corner;
  geometry.dx = g.cell_size;
  for (int d = 0; d < 3; ++d)
    geometry.cells[d] = static_cast<int>(std::ceil((g.upper_corner[d] - g.lower_corner[d]) / g.cell_size - 1e-9));
  return geometry;
}

// Colliders and domain walls.
boundary::Boundary make_boundary(const scene::SceneConfig& scene) {
  std::vector<boundary::Collider> colliders = make_colliders(scene);
  boundary::DomainWalls walls;
  walls.type = boundary::contact_type_from_name(scene.grid.walls);
  walls.thickness = scene.grid.wall_thickness;
  return boundary::Boundary(std::move(colliders), walls, make_inflows(scene));
}

// The particles of all bodies that this rank owns (ids independent of the rank count).
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
    const std::size_t first = set.size();
    particles::sample_body(sampling, grid, id_offset,
                           [&](const Vec3& x) { return parallel::particle_owner(decomposition, grid, order, x) == rank; },
                           set);
    for (const auto& region : make_regions(scene, body.name, materials)) particles::assign_region(region, first, set);
    id_offset += particles::lattice_size(sampling, grid);
  }
  return set;
}
}  // namespace

namespace {
// The emitters' layer counts a checkpoint carries (a restart in the middle of emission).
void restore_emitters(std::vector<particles::Emitter>& emitters, const std::vector<double>& layers,
                      const std::string& restart_file) {
  if (layers.size() != emitters.size())
    throw InputError(restart_file + ": it holds " + std::to_string(layers.size()) + " emitters, the scene " +
                     std::to_string(emitters.size()));
  for (std::size_t k = 0; k < emitters.size(); ++k) emitters[k].set_layers_emitted(static_cast<std::int64_t>(layers[k]));
}
}  // namespace

Simulation::Simulation(const scene::SceneConfig& scene, const linalg::SolverConfiguration& solver,
                       const parallel::Communicator& comm, const std::string& restart_file)
    : Simulation(scene, make_materials(scene), solver, comm, restart_file) {}

Simulation::Simulation(const scene::SceneConfig& scene, materials::MaterialList materials,
                       const linalg::SolverConfiguration& solver, const parallel::Communicator& comm,
                       const std::string& restart_file)
    : scene_(scene),
      comm_(comm),
      geometry_(make_grid(scene.grid)),
      order_(grid::kernel_order_from_name(scene.simulation.kernel)),
      decomposition_(std::make_unique<parallel::BlockDecomposition>(geometry_, comm.size())),
      materials_(std::move(materials)),
      boundary_(make_boundary(scene)),
      time_step_cap_(scene.simulation.max_time_step) {
  std::vector<double> emitter_layers;  // from the checkpoint
  if (materials_.size() != scene.materials.size())
    throw std::invalid_argument("Simulation: one material per scene material expected");
  if (restart_file.empty()) {
    check_memory(scene, comm_);
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
    emitter_layers = state.emitter_layers;
    balanced_imbalance_ = state.balanced_imbalance;
    restarted_ = true;
    // A checkpoint of another scene or grid: its particles lie outside this grid.
    const Vec3 lo = geometry_.origin, hi = geometry_.origin + geometry_.dx * geometry_.cells.cast<double>();
    bool outside = false;
    for (const Vec3& x : particles_.position) outside |= (x.array() < lo.array()).any() || (x.array() > hi.array()).any();
    if (comm_.any(outside))
      throw InputError(restart_file + ": particles lie outside the scene's grid (a checkpoint of another scene?)");
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
  emitters_ = make_emitters(scene, geometry_, materials_);
  if (restarted_) restore_emitters(emitters_, emitter_layers, restart_file);
  else emit_particles();
  if (comm_.sum(static_cast<std::int64_t>(particles_.size())) == 0)
    throw InputError(scene.file + ": parameter 'Bodies': no particle falls inside the grid");
  boundary_.clamp_particles(geometry_, particles_.position);
  IntegratorSettings settings;
  settings.gravity = scene.simulation.gravity;
  settings.transfer.scheme = transfer::scheme_from_name(scene.simulation.transfer);
  settings.transfer.flip_ratio = scene.simulation.flip_ratio;
  settings.newton = scene.newton;
  settings.delete_outside_particles = scene.grid.outside_particles == "delete";
  settings.padding.margin = scene.grid.padding_cells;
  settings.padding.lookahead = scene.grid.padding_lookahead;
  integrator_ = std::make_unique<TimeIntegrator>(comm_, geometry_, order_, *decomposition_, settings, materials_,
                                                 boundary_, solver);
}

double Simulation::suggested_time_step() const {
  double speed = 0.0;
  for (const Vec3& v : particles_.velocity) speed = std::max(speed, v.norm());
  for (const auto& c : boundary_.colliders()) speed = std::max(speed, c.max_speed());
  for (const auto& e : emitters_) speed = std::max(speed, e.spec().velocity.norm());
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
  if (before <= std::max(threshold, rebalance_slack * balanced_imbalance_)) return;
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

bool Simulation::advance_to(double t_end, RunSummary& summary, std::ostream* log) {
  while (time_ < t_end * (1.0 - end_tolerance)) {
    rebalance_if_needed(summary, log);
    emit_particles();
    double dt = suggested_time_step();
    const double remaining = t_end - time_;
    if (dt >= remaining * (1.0 - landing_tolerance)) dt = remaining;
    else if (dt > sliver_fraction * remaining) dt = sliver_fraction * remaining;
    take_step(dt, summary, log);  // abandoned (time and step unchanged) on a stop request
    if (in_run_ && stop_requested(summary, log)) return false;
  }
  time_ = t_end;
  return true;
}

void Simulation::take_step(double dt, RunSummary& summary, std::ostream* log) {
  const double min_dt = scene_.simulation.min_time_step;
  std::string dump_prefix;
  for (double s : scene_.output.matrix_market_steps)
    if (static_cast<std::int64_t>(s) == step_ + 1)
      dump_prefix = scene_.output.directory + "/newton_step_" + std::to_string(step_ + 1);
  for (;;) {
    before_step_ = particles_;  // a step that goes non-finite is retried from here
    const StepReport report = integrator_->step(particles_, time_, dt, dump_prefix);
    const auto& newton = report.newton;
    for (std::size_t k = 0; k < newton.linear_solves.size(); ++k) {
      const auto& solve = newton.linear_solves[k];
      if (solver_log_) solver_log_->record(step_ + 1, static_cast<int>(k + 1), solve);
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
    if (newton.interrupted) {  // a stop request: the state stays that of the step's start
      particles_ = before_step_;
      return;
    }
    std::string failure;
    if (!newton.converged) {
      failure = "Newton failed (" + newton.failure + ")";
    } else if (!state_is_finite()) {
      failure = "the step produced non-finite particle values";
      particles_ = before_step_;
    }
    if (failure.empty()) {
      summary.ghost_particle_steps += comm_.sum(static_cast<std::int64_t>(report.ghost_particles));
      summary.particles_deleted += comm_.sum(static_cast<std::int64_t>(report.particles_deleted));
      summary.particles_migrated += comm_.sum(static_cast<std::int64_t>(report.particles_sent));
      summary.shared_node_steps += comm_.sum(static_cast<std::int64_t>(report.shared_nodes));
      summary.owned_node_steps += comm_.sum(static_cast<std::int64_t>(report.owned_nodes));
      break;
    }
    ++summary.retries;
    const double reduction = scene_.simulation.time_step_reduction;
    if (dt * reduction < min_dt)
      throw SimulationError("at t = " + std::to_string(time_) + " with the smallest Δt: " + failure +
                            "; the last frame written is frame " + std::to_string(frame_));
    if (log && comm_.is_root() && ++retries_reported_ <= retries_logged)
      *log << "  step " << step_ + 1 << ": " << failure << " at Δt = " << dt << ", retrying with Δt × " << reduction
           << (newton.converged ? std::string() : " [" + newton.history() + "]")
           << (retries_reported_ == retries_logged ? " (further retries are counted, not shown)" : "") << "\n";
    dt *= reduction;
    time_step_cap_ = dt;
  }
  time_ += dt;
  ++step_;
  ++summary.steps;
  time_step_cap_ = std::min(scene_.simulation.time_step_growth * time_step_cap_, scene_.simulation.max_time_step);
}

bool Simulation::state_is_finite() const {
  bool finite = true;
  particles_.for_each_field([&](const char*, const auto& field) {
    using T = typename std::decay_t<decltype(field)>::value_type;
    if constexpr (std::is_same_v<T, Vec3> || std::is_same_v<T, Mat3>) {
      for (const auto& value : field) finite &= value.allFinite();
    } else if constexpr (std::is_same_v<T, double>) {
      for (double value : field) finite &= std::isfinite(value);
    }
  });
  return !comm_.any(!finite);
}

bool Simulation::stop_requested(RunSummary& summary, std::ostream* log) {
  // One agreement per step: a signal may reach only some ranks, the clocks differ, and only
  // rank 0 writes solver.csv.
  const double wall = scene_.output.checkpoint_wall_seconds;
  const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - last_checkpoint_time_).count();
  double flags[3] = {static_cast<double>(stop_signal()), wall > 0.0 && elapsed >= wall ? 1.0 : 0.0,
                     solver_log_ && !solver_log_->good() ? 1.0 : 0.0};
  MPI_Allreduce(MPI_IN_PLACE, flags, 3, MPI_DOUBLE, MPI_MAX, comm_.comm());
  if (flags[2] > 0.0)
    throw SimulationError("cannot write " + solver_log_->path() + ": " + io::write_failure_reason(solver_log_->path()));
  if (flags[0] == 0.0 && flags[1] == 0.0) return false;
  // A checkpoint between frames, replacing the one this run wrote before.
  const std::string previous = wall_checkpoint_;
  wall_checkpoint_ = write_checkpoint_file(io::step_checkpoint_file_name(step_));
  last_checkpoint_time_ = std::chrono::steady_clock::now();
  if (comm_.is_root() && !previous.empty() && previous != wall_checkpoint_) {
    std::error_code ignored;
    std::filesystem::remove(previous, ignored);
  }
  if (flags[0] == 0.0) {
    if (log && comm_.is_root()) *log << "  step " << step_ << ": checkpoint " << wall_checkpoint_ << "\n";
    return false;
  }
  summary.stop_signal = static_cast<int>(flags[0]);
  summary.stop_checkpoint = wall_checkpoint_;
  return true;
}

namespace {
std::string clock_text(double seconds) {
  const long s = std::lround(std::max(seconds, 0.0));
  std::ostringstream out;
  out << s / 60 << ":" << std::setw(2) << std::setfill('0') << s % 60;
  return out.str();
}
}  // namespace

std::string Simulation::write_checkpoint() { return write_checkpoint_file(io::checkpoint_file_name(frame_)); }

std::string Simulation::write_checkpoint_file(const std::string& name) {
  integrator_->reset_reuse();  // continue as a run restarted from this checkpoint starts
  io::RunState state{time_, step_, frame_, time_step_cap_, scene_.name, {}, {}, balanced_imbalance_};
  if (const auto* boxes = dynamic_cast<const parallel::BoxDecomposition*>(decomposition_.get()))
    for (const auto& b : boxes->boxes())
      state.decomposition_boxes.insert(state.decomposition_boxes.end(),
                                       {b.lower.x(), b.lower.y(), b.lower.z(), b.upper.x(), b.upper.y(), b.upper.z()});
  for (const auto& e : emitters_) state.emitter_layers.push_back(static_cast<double>(e.layers_emitted()));
  const std::string path = (std::filesystem::path(scene_.output.directory) / name).string();
  io::write_checkpoint(path, state, particles_, materials_, comm_);
  return path;
}

void Simulation::write_frame(int frame) {
  frame_ = frame;
  frames_.push_back(
      io::write_frame(scene_.output.directory, {frame, time_, step_, 0}, particles_, materials_, comm_, frame_extras()));
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

RunSummary Simulation::run(std::ostream& log) {
  const std::string& directory = scene_.output.directory;
  std::error_code error;
  if (comm_.is_root()) std::filesystem::create_directories(directory, error);
  if (comm_.any(comm_.is_root() && (error || !std::filesystem::is_directory(directory))))
    throw InputError(scene_.file + ": parameter 'Output/Directory': cannot create '" + directory + "'");
  solver_log_ = std::make_unique<io::SolverLog>(directory, comm_.is_root(), comm_.size(), restarted_);
  if (comm_.any(!solver_log_->good()))
    throw SimulationError("cannot write " + solver_log_->path() + ": " + io::write_failure_reason(solver_log_->path()));

  RunSummary summary;
  const auto start = std::chrono::steady_clock::now();
  last_checkpoint_time_ = start;
  in_run_ = true;
  integrator_->set_interrupt([] { return stop_signal() != 0; });  // a stop request abandons the step
  struct Leave {  // advance_to outside run() ignores stop requests again, however run() ends
    TimeIntegrator& integrator;
    bool& flag;
    ~Leave() {
      flag = false;
      integrator.set_interrupt({});
    }
  } leave{*integrator_, in_run_};
  if (restarted_) {
    if (comm_.is_root()) frames_ = existing_frames(directory, frame_);  // for the XDMF index
  } else {
    write_frame(0);
  }
  const int frames = scene_.simulation.frames;
  const double frame_duration = 1.0 / scene_.simulation.frame_rate;
  const std::int64_t particle_count = comm_.sum(static_cast<std::int64_t>(particles_.size()));
  if (comm_.is_root())
    log << scene_.name << ": " << particle_count << " particles, grid " << geometry_.cells.transpose() << " cells of "
        << geometry_.dx << " m, " << comm_.size() << " rank(s), " << frames << " frames"
        << (restarted_ ? ", restarted at t = " + std::to_string(time_) + " (frame " + std::to_string(frame_) + ")"
                       : std::string())
        << "\n";
  for (const auto& e : emitters_)
    if (comm_.is_root())
      log << "  emitter " << e.spec().name << ": " << e.layer_size() << " particles per layer, "
          << e.layer_size() / e.layer_interval() << " particles/s, "
          << e.particle_mass() * e.layer_size() / e.layer_interval() << " kg/s\n";
  const int first = frame_ + 1;
  for (int frame = first; frame <= frames; ++frame) {
    if (!advance_to(frame * frame_duration, summary, &log)) break;
    write_frame(frame);
    const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const int done = frame - first + 1;
    if (comm_.is_root())
      log << "frame " << std::setw(4) << frame << "/" << frames << "  t = " << std::setprecision(4) << std::fixed
          << time_ << " s  steps " << summary.steps << "  newton " << summary.newton_iterations << "  cg "
          << summary.linear_iterations << "  graphs " << summary.graph_builds << "  retries " << summary.retries
          << "  wall " << clock_text(elapsed)
          << "  eta " << clock_text(elapsed / done * (frames - frame)) << std::defaultfloat << std::endl;
  }
  summary.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  solver_log_.reset();
  return summary;
}

void Simulation::emit_particles() {
  const int rank = comm_.rank();
  for (auto& emitter : emitters_)
    emitter.emit(time_, [&](const Vec3& x) { return parallel::particle_owner(*decomposition_, geometry_, order_, x) == rank; },
                 particles_);
}

double Simulation::emitted_mass() const {
  double mass = 0.0;
  for (const auto& e : emitters_) mass += e.delivered_mass();
  return mass;
}

io::FrameExtras Simulation::frame_extras() const {
  io::FrameExtras extras;
  io::add_collider_surfaces(boundary_, time_, geometry_.origin, geometry_.upper_corner(), extras);
  extras.emitted_mass = emitted_mass();
  return extras;
}

void Simulation::write_surface(int frame) const {
  // The particles of all ranks on rank 0, as spheres of the particle spacing (h = V0^(1/3)).
  std::vector<double> local;
  double spacing = 0.0;
  for (std::size_t p = 0; p < particles_.size(); ++p) {
    local.insert(local.end(), particles_.position[p].data(), particles_.position[p].data() + 3);
    spacing = std::max(spacing, std::cbrt(particles_.volume0[p]));
  }
  const std::vector<double> all = comm_.all_gather(local);
  spacing = comm_.max(spacing);
  if (!comm_.is_root() || all.empty()) return;
  std::vector<Vec3> positions(all.size() / 3);
  for (std::size_t p = 0; p < positions.size(); ++p) positions[p] = Vec3(all[3 * p], all[3 * p + 1], all[3 * p + 2]);
  std::ostringstream name;
  name << scene_.output.directory << "/surface_" << std::setw(5) << std::setfill('0') << frame;
  const geometry::TriangleMesh surface =
      geometry::particle_surface(positions, spacing, scene_.output.surface_voxel_size, name.str() + ".vdb");
  geometry::write_obj(surface, name.str() + ".obj");
}

}  // namespace viscompm::simulation
