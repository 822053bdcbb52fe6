#include "viscompm/simulation/run_setup.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

#include "viscompm/core/error.hpp"
#include "viscompm/io/checkpoint.hpp"
#include "viscompm/io/frame_writer.hpp"
#include "viscompm/parallel/migration.hpp"
#include "viscompm/particles/sampling.hpp"
#include "viscompm/simulation/scene_objects.hpp"

namespace viscompm::simulation {

double SimulationState::emitted_mass() const {
  double mass = 0.0;
  for (const auto& e : emitters) mass += e.delivered_mass();
  return mass;
}

io::RunState SimulationState::record(const std::string& scene_name) const {
  io::RunState state{time, step, frame, time_step_cap, scene_name, {}, {}, balanced_imbalance};
  if (const auto* boxes = dynamic_cast<const parallel::BoxDecomposition*>(decomposition.get()))
    for (const auto& b : boxes->boxes())
      state.decomposition_boxes.insert(state.decomposition_boxes.end(),
                                       {b.lower.x(), b.lower.y(), b.lower.z(), b.upper.x(), b.upper.y(), b.upper.z()});
  for (const auto& e : emitters) state.emitter_layers.push_back(static_cast<double>(e.layers_emitted()));
  return state;
}

materials::MaterialList make_materials(const scene::SceneConfig& scene) {
  scene::SceneConfig linked = scene;  // a scene built in code names its models
  scene::link_names(linked);
  materials::MaterialList list;
  for (const auto& m : linked.materials) list.push_back(m.entry->create(m.name, m.values));
  return list;
}

// ---------------------------------------------------------------------------------------------
// The estimate of memory.
namespace {
/// Memory per particle: the default scene's peak memory grows by 3.2 KiB per particle with the
/// assembled Hessian and Jacobi (doc/contracts.md; MueLu needs more).
constexpr double bytes_per_particle = 4096.0;
/// Peak memory of a frame's particle surface (OpenVDB ParticlesToLevelSet) per voxel of a 6-voxel
/// band over the particles' surface (measured: 106 bytes, the default scene at 1 and 0.5 mm).
constexpr double surface_bytes_per_voxel = 110.0;

double gib(double bytes) { return bytes / 1073741824.0; }

// Particles of a body: the lattice sites of its bounding box inside the grid (what sampling
// visits), times the shape's share of its box. In doubles: nothing overflows.
double body_particles(const scene::SceneConfig& scene, const scene::BodySettings& body) {
  const Shape shape = scene::shape_of(body);
  Vec3 lo, hi;
  shape.bounding_box(lo, hi);
  const double h = scene.grid.cell_size / body.particles_per_cell;
  double sites = 1.0;
  for (int d = 0; d < 3; ++d)
    sites *= std::max(0.0, std::min(hi[d], scene.grid.upper_corner[d]) - std::max(lo[d], scene.grid.lower_corner[d])) / h;
  const double share = shape.kind == Shape::Kind::sphere ? M_PI / 6.0 : shape.kind == Shape::Kind::cylinder ? M_PI / 4.0 : 1.0;
  return sites * share;
}

// Particles an emitter adds over the run (at least one layer, which is laid out when the run is
// set up): its rate times its time, in particles of h³ (a continuous stream: a layer of the
// nozzle's cross-section per h of travel).
double emitted_particles(const scene::SceneConfig& scene, const scene::EmitterSettings& e) {
  const double end = std::min(e.stop_time, scene.simulation.frames / scene.simulation.frame_rate);
  const double duration = std::max(0.0, end - e.start_time);
  const double h = scene.grid.cell_size / e.particles_per_cell;
  // Cross-section: a disc's, else the nozzle box's projection along the velocity.
  const Vec3 n = e.velocity.normalized();
  double area = M_PI * e.radius * e.radius;
  if (e.shape != scene::ShapeKind::disc) {
    Vec3 lo, hi;
    scene::shape_of(e).bounding_box(lo, hi);
    const Vec3 a = hi - lo;
    area = std::abs(n.x()) * a.y() * a.z() + std::abs(n.y()) * a.x() * a.z() + std::abs(n.z()) * a.x() * a.y();
  }
  const double layer = area / (h * h);
  if (e.mass_rate > 0.0) {
    const double density = scene.materials[e.material_id].values.real("Density");
    return std::max(layer, e.mass_rate * duration / (density * h * h * h));
  }
  return layer * std::max(1.0, e.velocity.norm() * duration / h);
}

// The surface a frame's particles are wrapped in: the bodies' boxes, and the emitted particles
// packed into a cube.
double particle_surface_area(const scene::SceneConfig& scene) {
  double area = 0.0;
  for (const auto& b : scene.bodies) {
    Vec3 lo, hi;
    scene::shape_of(b).bounding_box(lo, hi);
    const Vec3 a = hi.cwiseMin(scene.grid.upper_corner) - lo.cwiseMax(scene.grid.lower_corner);
    if ((a.array() > 0.0).all()) area += 2.0 * (a.x() * a.y() + a.y() * a.z() + a.x() * a.z());
  }
  for (const auto& e : scene.emitters) {
    const double h = scene.grid.cell_size / e.particles_per_cell;
    area += 6.0 * std::pow(emitted_particles(scene, e) * h * h * h, 2.0 / 3.0);
  }
  return area;
}

[[noreturn]] void too_large(const scene::SceneConfig& scene, const std::string& parameter, const std::string& what,
                            double needed, double available, int ranks) {
  std::ostringstream reason;
  reason << std::setprecision(3) << what << ", ";
  if (std::isfinite(needed)) reason << "an estimated " << gib(needed) << " GiB, ";
  reason << "more than the " << gib(available) << " GiB of memory of " << ranks << " rank(s)";
  throw parameter_error(scene.file, parameter, reason.str());
}
}  // namespace

void check_memory(const scene::SceneConfig& scene, const parallel::Communicator& comm) {
  // The particles: the bodies' and every emitter's; the largest share names the parameter.
  double particles = 0.0, largest = 0.0;
  std::string parameter = "Grid/Cell size";
  for (const auto& body : scene.bodies) particles += body_particles(scene, body);
  largest = particles;
  for (const auto& e : scene.emitters) {
    const double emitted = emitted_particles(scene, e);
    particles += emitted;
    if (emitted > largest) {
      largest = emitted;
      parameter = "Emitters/" + e.name + (e.mass_rate > 0.0 ? "/Mass rate" : "/Velocity");
    }
  }
  const double available = comm.sum(parallel::memory_per_rank(comm));
  std::ostringstream what;
  what << std::setprecision(3) << "about " << particles << " particles (" << bytes_per_particle / 1024.0
       << " KiB per particle)";
  if (!(particles * bytes_per_particle <= available))
    too_large(scene, parameter, what.str(), particles * bytes_per_particle, available, comm.size());
  // A frame's surface, built on rank 0.
  const double voxel = scene.output.surface_voxel_size;
  if (voxel <= 0.0) return;
  const double voxels = 6.0 * particle_surface_area(scene) / (voxel * voxel);
  const double rank_memory = comm.min(parallel::memory_per_rank(comm));
  std::ostringstream surface;
  surface << std::setprecision(3) << "the particles' surface spans about " << voxels << " voxels ("
          << surface_bytes_per_voxel << " bytes each)";
  if (!(voxels * surface_bytes_per_voxel <= rank_memory))
    too_large(scene, "Output/Surface voxel size", surface.str(), voxels * surface_bytes_per_voxel, rank_memory, 1);
}

// ---------------------------------------------------------------------------------------------
// The objects of a run.
grid::GridGeometry make_grid(const scene::GridSettings& g) {
  grid::GridGeometry geometry;
  geometry.origin = g.lower_corner;
  geometry.dx = g.cell_size;
  for (int d = 0; d < 3; ++d)
    geometry.cells[d] = static_cast<int>(std::ceil((g.upper_corner[d] - g.lower_corner[d]) / g.cell_size - 1e-9));
  return geometry;
}

boundary::Boundary make_boundary(const scene::SceneConfig& scene) {
  boundary::DomainWalls walls;
  walls.type = scene.grid.walls;
  walls.thickness = scene.grid.wall_thickness;
  return boundary::Boundary(make_colliders(scene), walls, make_inflows(scene));
}

IntegratorSettings integrator_settings(const scene::SceneConfig& scene) {
  IntegratorSettings settings;
  settings.gravity = scene.simulation.gravity;
  settings.transfer.scheme = scene.simulation.transfer;
  settings.transfer.flip_ratio = scene.simulation.flip_ratio;
  settings.newton = scene.newton;
  settings.delete_outside_particles = scene.grid.outside_particles == scene::OutsideParticles::remove;
  settings.padding.margin = scene.grid.padding_cells;
  settings.padding.lookahead = scene.grid.padding_lookahead;
  return settings;
}

// ---------------------------------------------------------------------------------------------
// The state a run starts from.
namespace {
// The particles of all bodies that this rank owns (ids independent of the rank count).
particles::ParticleSet sample_particles(const scene::SceneConfig& scene, const grid::GridGeometry& grid,
                                        grid::KernelOrder order, const parallel::Decomposition& decomposition,
                                        const materials::MaterialList& materials, int rank) {
  particles::ParticleSet set;
  ParticleId id_offset = 0;
  for (std::size_t b = 0; b < scene.bodies.size(); ++b) {
    const auto& body = scene.bodies[b];
    particles::BodySampling sampling;
    sampling.shape = scene::shape_of(body);
    sampling.particles_per_cell = body.particles_per_cell;
    sampling.velocity = body.velocity;
    sampling.angular_velocity = body.angular_velocity;
    sampling.material_id = body.material_id;
    sampling.density = materials[sampling.material_id]->density();
    const std::size_t first = set.size();
    particles::sample_body(sampling, grid, id_offset,
                           [&](const Vec3& x) { return parallel::particle_owner(decomposition, grid, order, x) == rank; },
                           set);
    for (const auto& region : make_regions(scene, static_cast<int>(b), materials)) particles::assign_region(region, first, set);
    id_offset += particles::lattice_size(sampling, grid);
  }
  return set;
}

// The state a checkpoint holds, its particles migrated to their owners; InputError if it is not
// this scene's.
void restore(const std::string& restart_file, const grid::GridGeometry& grid, grid::KernelOrder order,
             const materials::MaterialList& materials, const parallel::Communicator& comm, SimulationState& state) {
  io::RunState saved;
  std::string names;
  state.particles = io::read_checkpoint(restart_file, comm, saved, names);
  if (names != io::material_names(materials))
    throw InputError(restart_file + ": its materials (" + names + ") are not the scene's (" +
                     io::material_names(materials) + ")");
  state.time = saved.time;
  state.step = saved.step;
  state.frame = saved.frame;
  state.time_step_cap = saved.time_step_cap;
  state.balanced_imbalance = saved.balanced_imbalance;
  state.restarted = true;
  // A checkpoint of another scene or grid: its particles lie outside this grid.
  const Vec3 lo = grid.origin, hi = grid.upper_corner();
  bool outside = false;
  for (const Vec3& x : state.particles.position) outside |= (x.array() < lo.array()).any() || (x.array() > hi.array()).any();
  if (comm.any(outside))
    throw InputError(restart_file + ": particles lie outside the scene's grid (a checkpoint of another scene?)");
  // The same rank count continues with the same ownership (bit-for-bit restarts).
  if (saved.decomposition_boxes.size() == 6u * static_cast<std::size_t>(comm.size())) {
    std::vector<parallel::BoxDecomposition::Box> boxes(comm.size());
    for (int r = 0; r < comm.size(); ++r) {
      const double* b = saved.decomposition_boxes.data() + 6 * r;
      boxes[r] = {Vec3(b[0], b[1], b[2]), Vec3(b[3], b[4], b[5])};
    }
    state.decomposition = std::make_unique<parallel::BoxDecomposition>(grid, std::move(boxes));
  }
  parallel::migrate_particles(comm, *state.decomposition, grid, order, state.particles);
  if (saved.emitter_layers.size() != state.emitters.size())
    throw InputError(restart_file + ": it holds " + std::to_string(saved.emitter_layers.size()) + " emitters, the scene " +
                     std::to_string(state.emitters.size()));
  for (std::size_t k = 0; k < state.emitters.size(); ++k)
    state.emitters[k].set_layers_emitted(static_cast<std::int64_t>(saved.emitter_layers[k]));
}
}  // namespace

SimulationState initial_state(const scene::SceneConfig& scene, const grid::GridGeometry& grid, grid::KernelOrder order,
                              const materials::MaterialList& materials, const boundary::Boundary& boundary,
                              const parallel::Communicator& comm, const std::optional<std::string>& restart_file) {
  SimulationState state;
  state.time_step_cap = scene.simulation.max_time_step;
  try {
    state.decomposition = std::make_unique<parallel::BlockDecomposition>(grid, comm.size());
  } catch (const InputError& e) {
    throw parameter_error(scene.file, "Grid/Cell size", e.what());
  }
  if (!restart_file) check_memory(scene, comm);  // before any layer or body is laid out
  state.emitters = make_emitters(scene, grid, materials);
  if (!restart_file) {
    state.particles = sample_particles(scene, grid, order, *state.decomposition, materials, comm.rank());
    for (auto& emitter : state.emitters)
      emitter.emit(0.0, [&](const Vec3& x) { return parallel::particle_owner(*state.decomposition, grid, order, x) == comm.rank(); },
                   state.particles);
  } else {
    restore(*restart_file, grid, order, materials, comm, state);
  }
  if (comm.sum(static_cast<std::int64_t>(state.particles.size())) == 0)
    throw parameter_error(scene.file, "Bodies", "no particle falls inside the grid");
  boundary.clamp_particles(grid, state.particles.position);
  return state;
}

}  // namespace viscompm::simulation
