#include "viscompm/scene/scene.hpp"

#include <Teuchos_ParameterList.hpp>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <sstream>

#include "viscompm/core/error.hpp"
#include "viscompm/core/shape.hpp"
#include "viscompm/geometry/level_set.hpp"
#include "viscompm/materials/registry.hpp"
#include "viscompm/params/parameter_io.hpp"

namespace viscompm::scene {

using params::check_entries;
using params::parse_value;
using params::read_parameters;
using params::read_xml_file;
using params::set_entry;

const ParameterTable<SimulationSettings>& SimulationSettings::table() {
  static const ParameterTable<SimulationSettings> t = [] {
    ParameterTable<SimulationSettings> table;
    using S = SimulationSettings;
    table.integer(&S::frames, "Frames", 24, Range::at_least(0), "frames to simulate after frame 0")
        .real(&S::frame_rate, "Frame rate", 24.0, Range::positive(), "frames per second of simulated time")
        .real(&S::cfl, "CFL", 0.5, Range::open_closed(0.0, 10.0), "Δt ≤ CFL·Δx / max particle speed")
        .real(&S::max_time_step, "Max time step", 1e-2, Range::positive(), "upper bound of Δt [s]")
        .real(&S::min_time_step, "Min time step", 1e-7, Range::positive(),
              "smallest Δt tried when a step fails before the run stops [s]")
        .real(&S::time_step_growth, "Time step growth", 1.5, Range::open_closed(1.0, 10.0),
              "after each successful step the Δt cap grows by this factor (up to Max time step)")
        .real(&S::time_step_reduction, "Time step reduction", 0.5, {0.0, 1.0, false, false},
              "a step that fails (Newton, or non-finite values) is retried with Δt times this factor")
        .vector3(&S::gravity, "Gravity", Vec3(0.0, -9.81, 0.0), "gravitational acceleration [m/s^2]")
        .string(&S::transfer, "Transfer", "apic", {"apic", "pic_flip"}, "particle-grid transfer (§3.4, §5.6)")
        .real(&S::flip_ratio, "FLIP ratio", 0.95, Range::closed(0.0, 1.0), "α of the PIC/FLIP blend (pic_flip only)")
        .string(&S::kernel, "Kernel", "quadratic", {"quadratic", "cubic"}, "B-spline interpolation (§3.1)");
    return table;
  }();
  return t;
}

const ParameterTable<GridSettings>& GridSettings::table() {
  static const ParameterTable<GridSettings> t = [] {
    ParameterTable<GridSettings> table;
    using G = GridSettings;
    table.vector3(&G::lower_corner, "Lower corner", Vec3::Zero(), "lower corner of the domain [m]")
        .vector3(&G::upper_corner, "Upper corner", Vec3::Ones(), "upper corner of the domain [m]")
        .real(&G::cell_size, "Cell size", 0.05, Range::positive(), "grid spacing Δx [m]")
        .string(&G::walls, "Walls", "separating", {"sticky", "slip", "separating"}, "contact at the domain faces")
        .string(&G::outside_particles, "Outside particles", "clamp", {"clamp", "delete"},
                "particles that reach the last cell of the grid are held there (clamp) or removed and counted (delete)")
        .real(&G::rebalance_threshold, "Rebalance threshold", 1.25, Range::at_least(0.0),
              "re-partition the grid (Zoltan2 RCB of the particles) when the largest rank holds more than this "
              "times the mean particle count; 0 never")
        .integer(&G::wall_thickness, "Wall thickness", 2, Range::closed(1, 8),
                 "nodes closer than this many cells to a face are wall nodes")
        .integer(&G::padding_cells, "Padding cells", 0, Range::closed(0, 16),
                 "the linear system's nodes (and the Hessian's graph) reach this many cells beyond the occupied "
                 "ones; the graph is rebuilt when a particle leaves them")
        .real(&G::padding_lookahead, "Padding lookahead", 8.0, Range::closed(0.0, 1000.0),
              "and further along each cell's particle velocities, as far as they move in this many steps "
              "(at most 8 cells)");
    return table;
  }();
  return t;
}

namespace {
template <class S>
void add_shape_parameters(ParameterTable<S>& table,
                          std::vector<std::string> shapes = {"box", "sphere", "cylinder", "half_space", "mesh"}) {
  const bool mesh = std::find(shapes.begin(), shapes.end(), "mesh") != shapes.end();
  const bool cuts = std::find(shapes.begin(), shapes.end(), "cuts") != shapes.end();
  table.string(&S::shape, "Shape", shapes.front(), shapes, "solid shape")
      .vector3(&S::lower_corner, "Lower corner", Vec3::Zero(), "box: lower corner [m]")
      .vector3(&S::upper_corner, "Upper corner", Vec3::Ones(), "box: upper corner [m]")
      .vector3(&S::center, "Center", Vec3::Zero(), "sphere, cylinder: centre; half_space: a point on its plane [m]")
      .real(&S::radius, "Radius", 0.1, Range::positive(), "sphere, cylinder: radius [m]")
      .vector3(&S::axis, "Axis", Vec3::UnitY(), "cylinder: axis direction")
      .real(&S::length, "Length", 1.0, Range::positive(), "cylinder: length along its axis [m]")
      .vector3(&S::normal, "Normal", Vec3::UnitY(), "half_space: outward normal (the solid is below the plane)");
  if (mesh)
    table.string(&S::mesh_file, "File", "", {}, "mesh: OBJ or STL file (ASCII or binary), relative to the scene file")
        .real(&S::mesh_scale, "Scale", 1.0, Range::positive(), "mesh: its vertices x are placed at Scale·x + Center")
        .real(&S::voxel_size, "Voxel size", 0.0, Range::non_negative(),
              "mesh: voxel of its signed distance field [m] (0: a quarter of Grid/Cell size)");
  if (cuts)
    table.integer(&S::cut_count, "Cut count", 4, Range::closed(1, 64),
                  "cuts: planes through Center containing Axis, 180°/count apart (2·count slices)")
        .real(&S::cut_width, "Cut width", 0.01, Range::positive(), "cuts: thickness of each cut [m]");
}

Shape make_shape(const ShapeSettings& s, const std::string& file, const std::string& path) {
  Shape shape;
  shape.kind = Shape::kind_from_name(s.shape);
  shape.lower = s.lower_corner;
  shape.upper = s.upper_corner;
  shape.center = s.center;
  shape.radius = s.radius;
  shape.length = s.length;
  shape.field = s.field;
  shape.cut_count = s.cut_count;
  shape.cut_width = s.cut_width;
  if (shape.kind == Shape::Kind::mesh && !shape.field && !file.empty())
    throw InputError(file + ": parameter '" + path + "/File': no mesh loaded");
  const Vec3 direction = shape.kind == Shape::Kind::half_space ? s.normal : s.axis;
  if (direction.norm() == 0.0) throw InputError(file + ": parameter '" + path + "': direction must be non-zero");
  shape.axis = direction.normalized();
  if (shape.kind == Shape::Kind::box && !(s.upper_corner.array() > s.lower_corner.array()).all())
    throw InputError(file + ": parameter '" + path + "/Upper corner': must exceed Lower corner in every component");
  return shape;
}

// At most 2^53 grid nodes: their ids, and 3 per node for the Newton unknowns, stay exact in the
// 64-bit integers (and doubles) that hold them.
constexpr double max_grid_nodes = 9007199254740992.0;
// Cell indices per dimension are ints.
constexpr double max_cells_per_dimension = 1073741824.0;

constexpr const char* section_names[] = {"Simulation", "Grid", "Newton", "Solver", "Output", "Materials", "Bodies", "Colliders", "Emitters", "Regions"};

// Reads the mesh of a mesh shape, places it (Scale, Center) and builds its signed distance field;
// a body or region needs a closed mesh (it has an inside).
void load_mesh(ShapeSettings& s, const std::string& file, const std::string& path, double cell_size,
               bool must_be_closed) {
  if (s.shape != "mesh") return;
  const std::string where = file + ": parameter '" + path + "/File': ";
  if (s.mesh_file.empty()) throw InputError(where + "a mesh shape needs a file");
  const std::filesystem::path mesh_path = std::filesystem::path(s.mesh_file).is_absolute()
                                              ? std::filesystem::path(s.mesh_file)
                                              : std::filesystem::path(file).parent_path() / s.mesh_file;
  geometry::TriangleMesh mesh;
  try {
    mesh = geometry::transformed(geometry::read_mesh(mesh_path.lexically_normal().string()), s.mesh_scale, s.center);
  } catch (const InputError& e) {
    throw InputError(where + e.what());
  }
  if (must_be_closed && !geometry::is_closed(mesh))
    throw InputError(where + mesh_path.lexically_normal().string() +
                     ": the mesh is not closed (every edge must join two consistently oriented triangles)");
  s.field = std::make_shared<geometry::LevelSet>(mesh, s.voxel_size > 0.0 ? s.voxel_size : 0.25 * cell_size);
}

const std::vector<ParameterSpec>* fixed_section_specs(const std::string& section) {
  if (section == "Simulation") return &SimulationSettings::table().specs();
  if (section == "Grid") return &GridSettings::table().specs();
  if (section == "Newton") return &newton::NewtonSettings::table().specs();
  if (section == "Solver") return &SolverFileSettings::table().specs();
  if (section == "Output") return &OutputSettings::table().specs();
  if (section == "Bodies") return &BodySettings::table().specs();
  if (section == "Colliders") return &ColliderSettings::table().specs();
  if (section == "Emitters") return &EmitterSettings::table().specs();
  if (section == "Regions") return &RegionSettings::table().specs();
  return nullptr;
}

ParameterSpec model_spec() {
  ParameterSpec spec;
  spec.name = "Model";
  spec.type = ParameterSpec::Type::string;
  spec.default_value = std::string();
  spec.choices = materials::model_names();
  spec.doc = "constitutive model";
  return spec;
}

std::vector<std::string> split_path(const std::string& path) {
  std::vector<std::string> parts;
  std::stringstream in(path);
  for (std::string part; std::getline(in, part, '/');)
    if (!part.empty()) parts.push_back(part);
  return parts;
}

// The declaration of the parameter at `parts` (section[/item]/name) of `list`, or nullptr.
const ParameterSpec* find_spec(const Teuchos::ParameterList& list, const std::vector<std::string>& parts,
                               std::vector<ParameterSpec>& storage) {
  if (parts.size() < 2) return nullptr;
  const std::string& section = parts[0];
  const std::string& name = parts.back();
  const std::vector<ParameterSpec>* specs = nullptr;
  if (section == "Materials") {
    if (parts.size() != 3) return nullptr;
    storage = {model_spec()};
    const std::string* model = nullptr;
    if (list.isSublist("Materials") && list.sublist("Materials").isSublist(parts[1]))
      model = list.sublist("Materials").sublist(parts[1]).getPtr<std::string>("Model");
    if (model != nullptr)
      if (const auto* entry = materials::find_model(*model))
        storage.insert(storage.end(), entry->parameters.begin(), entry->parameters.end());
    specs = &storage;
  } else if (section == "Bodies" || section == "Colliders" || section == "Emitters" || section == "Regions") {
    if (parts.size() != 3) return nullptr;
    specs = fixed_section_specs(section);
  } else {
    if (parts.size() != 2) return nullptr;
    specs = fixed_section_specs(section);
  }
  if (specs == nullptr) return nullptr;
  for (const auto& s : *specs)
    if (s.name == name) return &s;
  return nullptr;
}

void apply_override(Teuchos::ParameterList& list, const Override& o, const std::string& file) {
  const auto parts = split_path(o.path);
  std::vector<ParameterSpec> storage;
  const ParameterSpec* spec = find_spec(list, parts, storage);
  if (spec == nullptr) throw InputError(file + ": --set '" + o.path + "': unknown parameter");
  Teuchos::ParameterList* target = &list;
  for (std::size_t k = 0; k + 1 < parts.size(); ++k) target = &target->sublist(parts[k]);
  try {
    set_entry(*target, parts.back(), parse_value(*spec, o.value));
  } catch (const InputError& e) {
    throw InputError(file + ": --set '" + o.path + "': " + e.what());
  }
}

template <class Settings>
Settings read_section(const Teuchos::ParameterList& root, const char* section, const std::string& file) {
  const Teuchos::ParameterList empty;
  const Teuchos::ParameterList& list = root.isSublist(section) ? root.sublist(section) : empty;
  return Settings::table().parse(read_parameters(list, Settings::table().specs(), file, section));
}

// Each sublist of `section`, read with `read(item_list, path)`.
template <class F>
void for_each_item(const Teuchos::ParameterList& root, const char* section, const std::string& file, F&& read) {
  if (!root.isSublist(section)) return;
  const Teuchos::ParameterList& list = root.sublist(section);
  for (auto it = list.begin(); it != list.end(); ++it) {
    const std::string path = std::string(section) + "/" + list.name(it);
    if (!list.entry(it).isList())
      throw InputError(file + ": parameter '" + path + "': expected a sublist (one per item)");
    read(list.name(it), Teuchos::getValue<Teuchos::ParameterList>(list.entry(it)), path);
  }
}
}  // namespace

const ParameterTable<BodySettings>& BodySettings::table() {
  static const ParameterTable<BodySettings> t = [] {
    ParameterTable<BodySettings> table;
    using B = BodySettings;
    add_shape_parameters(table);
    table.string(&B::material, "Material", "", {}, "name of a sublist of Materials")
        .integer(&B::particles_per_cell, "Particles per cell", 2, Range::closed(1, 8),
                 "particles per cell and dimension")
        .vector3(&B::velocity, "Velocity", Vec3::Zero(), "initial velocity [m/s]")
        .vector3(&B::angular_velocity, "Angular velocity", Vec3::Zero(),
                 "initial angular velocity about the shape's centre [rad/s]");
    return table;
  }();
  return t;
}

const ParameterTable<ColliderSettings>& ColliderSettings::table() {
  static const ParameterTable<ColliderSettings> t = [] {
    ParameterTable<ColliderSettings> table;
    using C = ColliderSettings;
    add_shape_parameters(table);
    table.string(&C::contact, "Contact", "sticky", {"sticky", "slip", "separating"},
                 "sticky: nodes inside move with the solid (Dirichlet grips); slip: normal only; separating: slip while approaching")
        .vector3(&C::velocity, "Velocity", Vec3::Zero(), "kinematic velocity [m/s]")
        .real(&C::start_time, "Start time", 0.0, Range::non_negative(), "time the solid starts moving [s]")
        .real(&C::stop_time, "Stop time", 1e30, Range::non_negative(), "time the solid stops moving [s]")
        .vector3(&C::angular_velocity, "Angular velocity", Vec3::Zero(),
                 "rotation rate ω about an axis through Rotation center [rad/s]: nodes move with v = Velocity + ω × (x − c)")
        .vector3(&C::rotation_center, "Rotation center", Vec3::Zero(),
                 "c: a point on the rotation axis at Start time (it moves with Velocity) [m]")
        .real_list(&C::keyframe_times, "Keyframe times", {}, Range::non_negative(),
                   "times of keyframes [s], increasing; if given they replace Velocity, Angular velocity and the times")
        .real_list(&C::keyframe_positions, "Keyframe positions", {}, Range::any(),
                   "translation of the solid at each keyframe, 3 numbers per keyframe [m] (linear in between)")
        .real_list(&C::keyframe_rotations, "Keyframe rotations", {}, Range::any(),
                   "rotation vector (axis·angle) about Rotation center at each keyframe, 3 numbers per keyframe [rad] "
                   "(constant angular velocity in between); empty: no rotation")
        .vector3(&C::surface_velocity, "Surface velocity", Vec3::Zero(),
                 "velocity of the solid's surface, tangential part only (a conveyor belt that stays in place) [m/s]");
    return table;
  }();
  return t;
}

const ParameterTable<EmitterSettings>& EmitterSettings::table() {
  static const ParameterTable<EmitterSettings> t = [] {
    ParameterTable<EmitterSettings> table;
    using E = EmitterSettings;
    add_shape_parameters(table, {"disc", "box", "cylinder"});
    table.string(&E::material, "Material", "", {}, "name of a sublist of Materials")
        .vector3(&E::velocity, "Velocity", Vec3::UnitX(),
                 "inflow velocity [m/s]: emitted particles and the nozzle's grid nodes move with it (disc: its normal)")
        .real(&E::mass_rate, "Mass rate", 0.0, Range::non_negative(),
              "emitted mass per second [kg/s]; 0: a continuous stream, density · nozzle area · speed")
        .real(&E::start_time, "Start time", 0.0, Range::non_negative(), "time the emission starts [s]")
        .real(&E::stop_time, "Stop time", 1e30, Range::non_negative(), "time the emission stops [s]")
        .integer(&E::particles_per_cell, "Particles per cell", 2, Range::closed(1, 8),
                 "particles per cell and dimension in each emitted layer");
    return table;
  }();
  return t;
}

const ParameterTable<RegionSettings>& RegionSettings::table() {
  static const ParameterTable<RegionSettings> t = [] {
    ParameterTable<RegionSettings> table;
    using R = RegionSettings;
    add_shape_parameters(table, {"box", "sphere", "cylinder", "mesh", "cuts"});
    table.string(&R::body, "Body", "", {}, "name of a sublist of Bodies whose particles the region re-assigns")
        .string(&R::material, "Material", "", {}, "name of a sublist of Materials: the particles' new material");
    return table;
  }();
  return t;
}

const ParameterTable<SolverFileSettings>& SolverFileSettings::table() {
  static const ParameterTable<SolverFileSettings> t = [] {
    ParameterTable<SolverFileSettings> table;
    table.string(&SolverFileSettings::file, "File", "../solvers/jacobi_cg.xml", {},
                 "solver XML, relative to the scene file (--solver overrides it)");
    return table;
  }();
  return t;
}

const ParameterTable<OutputSettings>& OutputSettings::table() {
  static const ParameterTable<OutputSettings> t = [] {
    ParameterTable<OutputSettings> table;
    table.string(&OutputSettings::directory, "Directory", "output", {},
                 "where frames, particles.xdmf and solver.csv go (--output overrides it)")
        .integer(&OutputSettings::checkpoint_every, "Checkpoint every", 0, Range::at_least(0),
                 "write DIR/checkpoint_NNNNN.h5 every this many frames (0: never); --restart continues from one")
        .real(&OutputSettings::checkpoint_wall_seconds, "Checkpoint wall seconds", 0.0, Range::non_negative(),
              "also write DIR/checkpoint_step_SSSSSSSS.h5 after the step in which this many wall-clock seconds have "
              "passed since the run started or last wrote one (the newer replaces the older); 0: never")
        .real_list(&OutputSettings::matrix_market_steps, "Matrix Market steps", {}, Range::at_least(1),
                   "steps whose first Newton system is written to DIR/newton_step_K.mtx and DIR/newton_step_K_rhs.mtx")
        .real(&OutputSettings::surface_voxel_size, "Surface voxel size", 0.0, Range::non_negative(),
              "> 0: write each frame's particle surface (OpenVDB level set of spheres of the particle spacing, "
              "voxels of this size [m]) to DIR/surface_NNNNN.obj and DIR/surface_NNNNN.vdb; 0: none");
    return table;
  }();
  return t;
}

Override Override::parse(const std::string& text) {
  const auto eq = text.find('=');
  if (eq == std::string::npos || eq == 0)
    throw InputError("--set '" + text + "': expected Path/To/Parameter=value");
  return {text.substr(0, eq), text.substr(eq + 1)};
}

namespace {
void check_keyframes(const ColliderSettings& c, const std::string& file, const std::string& path) {
  const std::size_t n = c.keyframe_times.size();
  if (n == 0) {
    if (!c.keyframe_positions.empty() || !c.keyframe_rotations.empty())
      throw InputError(file + ": parameter '" + path + "/Keyframe times': keyframes need their times");
    return;
  }
  for (std::size_t k = 1; k < n; ++k)
    if (!(c.keyframe_times[k] > c.keyframe_times[k - 1]))
      throw InputError(file + ": parameter '" + path + "/Keyframe times': must increase");
  if (c.keyframe_positions.size() != 3 * n)
    throw InputError(file + ": parameter '" + path + "/Keyframe positions': needs 3 numbers per keyframe time (" +
                     std::to_string(3 * n) + "), got " + std::to_string(c.keyframe_positions.size()));
  if (!c.keyframe_rotations.empty() && c.keyframe_rotations.size() != 3 * n)
    throw InputError(file + ": parameter '" + path + "/Keyframe rotations': needs 3 numbers per keyframe time (" +
                     std::to_string(3 * n) + "), got " + std::to_string(c.keyframe_rotations.size()));
}

bool has_material(const SceneConfig& scene, const std::string& name) {
  for (const auto& m : scene.materials)
    if (m.name == name) return true;
  return false;
}

void read_emitters_and_regions(const Teuchos::ParameterList& root, const std::string& file, SceneConfig& scene) {
  for_each_item(root, "Emitters", file, [&](const std::string& name, const Teuchos::ParameterList& list,
                                            const std::string& path) {
    EmitterSettings e = EmitterSettings::table().parse(read_parameters(list, EmitterSettings::table().specs(), file, path));
    e.name = name;
    if (!has_material(scene, e.material))
      throw InputError(file + ": parameter '" + path + "/Material': no material named '" + e.material + "'");
    if (e.velocity.norm() == 0.0) throw InputError(file + ": parameter '" + path + "/Velocity': must be non-zero");
    if (e.stop_time <= e.start_time) throw InputError(file + ": parameter '" + path + "/Stop time': must exceed Start time");
    if (e.shape == "disc") {
      // A disc: a cylinder two cells thick along the velocity, so that nodes lie inside it.
      e.shape = "cylinder";
      e.axis = e.velocity;
      e.length = 2.0 * scene.grid.cell_size;
    }
    make_shape(e, file, path);
    scene.emitters.push_back(e);
  });
  for_each_item(root, "Regions", file, [&](const std::string& name, const Teuchos::ParameterList& list,
                                           const std::string& path) {
    RegionSettings r = RegionSettings::table().parse(read_parameters(list, RegionSettings::table().specs(), file, path));
    r.name = name;
    if (!has_material(scene, r.material))
      throw InputError(file + ": parameter '" + path + "/Material': no material named '" + r.material + "'");
    bool known = false;
    for (const auto& b : scene.bodies) known |= b.name == r.body;
    if (!known) throw InputError(file + ": parameter '" + path + "/Body': no body named '" + r.body + "'");
    load_mesh(r, file, path, scene.grid.cell_size, true);
    make_shape(r, file, path);
    scene.regions.push_back(r);
  });
}
}  // namespace

SceneConfig read_scene(const std::string& file, const std::vector<Override>& overrides) {
  auto root = read_xml_file(file);
  for (const auto& o : overrides) apply_override(*root, o, file);

  SceneConfig scene;
  scene.file = file;
  scene.name = std::filesystem::path(file).stem().string();
  check_entries(*root, {}, std::vector<std::string>(std::begin(section_names), std::end(section_names)), file, "");
  scene.simulation = read_section<SimulationSettings>(*root, "Simulation", file);
  scene.grid = read_section<GridSettings>(*root, "Grid", file);
  scene.newton = read_section<newton::NewtonSettings>(*root, "Newton", file);
  scene.output = read_section<OutputSettings>(*root, "Output", file);
  const auto solver = read_section<SolverFileSettings>(*root, "Solver", file);
  const std::filesystem::path solver_path(solver.file);
  scene.solver_file = solver_path.is_absolute()
                          ? solver_path.string()
                          : (std::filesystem::path(file).parent_path() / solver_path).lexically_normal().string();
  if (!std::filesystem::is_regular_file(scene.solver_file))
    throw InputError(file + ": parameter 'Solver/File': cannot open '" + scene.solver_file + "'");

  for_each_item(*root, "Materials", file, [&](const std::string& name, const Teuchos::ParameterList& list,
                                              const std::string& path) {
    if (!list.isParameter("Model"))
      throw InputError(file + ": parameter '" + path + "/Model': missing (one of the registered models)");
    Teuchos::ParameterList model_only;  // the model first: it decides the other parameters
    model_only.setEntry("Model", list.getEntry("Model"));
    const ParameterValues model_value = read_parameters(model_only, {model_spec()}, file, path);
    const auto* entry = materials::find_model(model_value.string("Model"));
    std::vector<ParameterSpec> specs = {model_spec()};
    specs.insert(specs.end(), entry->parameters.begin(), entry->parameters.end());
    ParameterValues values = read_parameters(list, specs, file, path);
    if (entry->check)
      if (const auto problem = entry->check(values))
        throw InputError(file + ": parameter '" + path + "/" + problem->parameter + "': " + problem->reason);
    scene.materials.push_back({name, entry->model, std::move(values)});
  });
  for_each_item(*root, "Bodies", file, [&](const std::string& name, const Teuchos::ParameterList& list,
                                           const std::string& path) {
    BodySettings body = BodySettings::table().parse(read_parameters(list, BodySettings::table().specs(), file, path));
    body.name = name;
    bool known = false;
    for (const auto& m : scene.materials) known |= m.name == body.material;
    if (!known) throw InputError(file + ": parameter '" + path + "/Material': no material named '" + body.material + "'");
    if (body.shape == "half_space") throw InputError(file + ": parameter '" + path + "/Shape': a body must be bounded");
    load_mesh(body, file, path, scene.grid.cell_size, true);
    make_shape(body, file, path);
    scene.bodies.push_back(body);
  });
  for_each_item(*root, "Colliders", file, [&](const std::string& name, const Teuchos::ParameterList& list,
                                              const std::string& path) {
    ColliderSettings collider =
        ColliderSettings::table().parse(read_parameters(list, ColliderSettings::table().specs(), file, path));
    collider.name = name;
    load_mesh(collider, file, path, scene.grid.cell_size, false);
    make_shape(collider, file, path);
    check_keyframes(collider, file, path);
    scene.colliders.push_back(collider);
  });
  read_emitters_and_regions(*root, file, scene);

  // Cross-parameter checks.
  if (scene.bodies.empty() && scene.emitters.empty())
    throw InputError(file + ": parameter 'Bodies': the scene has no bodies (and no emitters)");
  if (!(scene.grid.upper_corner.array() > scene.grid.lower_corner.array()).all())
    throw InputError(file + ": parameter 'Grid/Upper corner': must exceed Lower corner in every component");
  const Vec3 extent = scene.grid.upper_corner - scene.grid.lower_corner;
  if (extent.minCoeff() < 2.0 * (scene.grid.wall_thickness + 2) * scene.grid.cell_size)
    throw InputError(file + ": parameter 'Grid/Cell size': the domain must be several cells wide in every direction");
  if (scene.simulation.min_time_step > scene.simulation.max_time_step)
    throw InputError(file + ": parameter 'Simulation/Min time step': exceeds Max time step");
  // Node ids are 64-bit integers and the Newton unknowns 3 per node: bound the grid before any
  // arithmetic in integers (doubles here, so that nothing overflows).
  double nodes = 1.0, widest = 0.0;
  for (int d = 0; d < 3; ++d) {
    nodes *= std::ceil(extent[d] / scene.grid.cell_size) + 1.0;
    widest = std::max(widest, std::ceil(extent[d] / scene.grid.cell_size));
  }
  if (nodes > max_grid_nodes || widest > max_cells_per_dimension) {
    std::ostringstream reason;
    reason << file << ": parameter 'Grid/Cell size': " << scene.grid.cell_size << " m makes " << nodes
           << " grid nodes (" << widest << " cells across), more than viscompm can number (" << max_grid_nodes
           << " nodes, " << max_cells_per_dimension << " cells across)";
    throw InputError(reason.str());
  }
  return scene;
}

Shape shape_of(const ShapeSettings& s) { return make_shape(s, "", ""); }

std::string describe_scene_parameters() {
  std::ostringstream out;
  auto section = [&](const std::string& title, const std::vector<ParameterSpec>& specs) {
    out << "  " << title << "\n";
    for (const auto& s : specs)
      out << "    " << s.name << " (" << ParameterSpec::type_name(s.type) << ", " << s.range_text() << "): " << s.doc
          << "\n";
  };
  section("Simulation", SimulationSettings::table().specs());
  section("Grid", GridSettings::table().specs());
  section("Newton", newton::NewtonSettings::table().specs());
  section("Solver", SolverFileSettings::table().specs());
  section("Output", OutputSettings::table().specs());
  section("Bodies/<name>", BodySettings::table().specs());
  section("Colliders/<name>", ColliderSettings::table().specs());
  section("Emitters/<name>", EmitterSettings::table().specs());
  section("Regions/<name>", RegionSettings::table().specs());
  for (const auto& m : materials::model_registry())
    section("Materials/<name> with Model = " + m.model + " (" + m.summary + ")", m.parameters);
  return out.str();
}

}  // namespace viscompm::scene
