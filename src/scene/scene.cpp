#include "viscompm/scene/scene.hpp"

#include <Teuchos_ParameterList.hpp>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <functional>
#include <limits>
#include <sstream>

#include "viscompm/core/error.hpp"
#include "viscompm/core/shape.hpp"
#include "viscompm/core/stop_request.hpp"
#include "viscompm/geometry/level_set.hpp"
#include "viscompm/materials/shared_parameters.hpp"
#include "viscompm/parallel/communicator.hpp"
#include "viscompm/params/parameter_io.hpp"
#include "default_solver_xml.hpp"  // generated: cmake/viscompmDefaultSolver.cmake

namespace viscompm::scene {

using params::check_entries;
using params::parse_value;
using params::read_parameters;
using params::read_xml_file;
using params::set_entry;

namespace {
const std::vector<std::pair<std::string, boundary::ContactType>> contact_words = {
    {"sticky", boundary::ContactType::sticky},
    {"slip", boundary::ContactType::slip},
    {"separating", boundary::ContactType::separating}};

std::string number_text(double x) {
  std::ostringstream s;
  s << x;
  return s.str();
}
}  // namespace

const ParameterTable<SimulationSettings>& SimulationSettings::table() {
  static const ParameterTable<SimulationSettings> t = [] {
    ParameterTable<SimulationSettings> table;
    using S = SimulationSettings;
    table.integer(&S::frames, "Frames", 24, Range::at_least(0), "frames to simulate after frame 0")
        .real(&S::frame_rate, "Frame rate", 24.0, Range::positive(), "frames per second of simulated time")
        .real(&S::cfl, "CFL", 0.5, Range::open_closed(0.0, 10.0), "Δt ≤ CFL·Δx / max particle speed")
        .real(&S::max_time_step, "Max time step", 1e-2, Range::positive(), "upper bound of Δt [s]")
        .real(&S::min_time_step, "Min time step", 1e-7, Range::positive(),
              "smallest Δt tried when a step fails before the run stops [s]; a speed whose CFL step is smaller "
              "is bad input")
        .real(&S::time_step_growth, "Time step growth", 1.5, Range::open_closed(1.0, 10.0),
              "after each successful step the Δt cap grows by this factor (up to Max time step)")
        .real(&S::time_step_reduction, "Time step reduction", 0.5, {0.0, 1.0, false, false},
              "a step that fails (Newton, or non-finite values) is retried with Δt times this factor")
        .vector3(&S::gravity, "Gravity", Vec3(0.0, -9.81, 0.0), "gravitational acceleration [m/s^2]")
        .choice(&S::transfer, "Transfer", transfer::Scheme::apic,
                {{"apic", transfer::Scheme::apic}, {"pic_flip", transfer::Scheme::pic_flip}},
                "particle-grid transfer (§3.4, §5.6)")
        .real(&S::flip_ratio, "FLIP ratio", 0.95, Range::closed(0.0, 1.0), "α of the PIC/FLIP blend (pic_flip only)")
        .choice(&S::kernel, "Kernel", grid::KernelOrder::quadratic,
                {{"quadratic", grid::KernelOrder::quadratic}, {"cubic", grid::KernelOrder::cubic}},
                "B-spline interpolation (§3.1)");
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
        .choice(&G::walls, "Walls", boundary::ContactType::separating, contact_words, "contact at the domain faces")
        .choice(&G::outside_particles, "Outside particles", OutsideParticles::clamp,
                {{"clamp", OutsideParticles::clamp}, {"delete", OutsideParticles::remove}},
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
// OpenVDB's transforms need a voxel whose cube is at least 3e-15 m³ (ScaleMap: "Non-zero scale
// values required" below).
constexpr double min_voxel_size = 1.5e-5;

template <class S>
void add_shape_parameters(ParameterTable<S>& table, const std::vector<std::pair<std::string, ShapeKind>>& shapes) {
  const auto has = [&](ShapeKind kind) {
    return std::any_of(shapes.begin(), shapes.end(), [&](const auto& s) { return s.second == kind; });
  };
  table.template choice<ShapeKind>(&S::shape, "Shape", shapes.front().second, shapes, "solid shape")
      .vector3(&S::lower_corner, "Lower corner", Vec3::Zero(), "box: lower corner [m]")
      .vector3(&S::upper_corner, "Upper corner", Vec3::Ones(), "box: upper corner [m]")
      .vector3(&S::center, "Center", Vec3::Zero(), "sphere, cylinder: centre; half_space: a point on its plane [m]")
      .real(&S::radius, "Radius", 0.1, Range::positive(), "sphere, cylinder: radius [m]")
      .vector3(&S::axis, "Axis", Vec3::UnitY(), "cylinder: axis direction")
      .real(&S::length, "Length", 1.0, Range::positive(), "cylinder: length along its axis [m]")
      .vector3(&S::normal, "Normal", Vec3::UnitY(), "half_space: outward normal (the solid is below the plane)");
  if (has(ShapeKind::mesh))
    table.string(&S::mesh_file, "File", "", {}, "mesh: OBJ or STL file (ASCII or binary), relative to the scene file")
        .real(&S::mesh_scale, "Scale", 1.0, Range::positive(), "mesh: its vertices x are placed at Scale·x + Center")
        .real(&S::voxel_size, "Voxel size", 0.0, Range::non_negative(),
              "mesh: voxel of its signed distance field [m] (0: a quarter of Grid/Cell size; else at least 1.5e-5, "
              "OpenVDB's smallest)");
  if (has(ShapeKind::cuts))
    table.integer(&S::cut_count, "Cut count", 4, Range::closed(1, 64),
                  "cuts: planes through Center containing Axis, 180°/count apart (2·count slices)")
        .real(&S::cut_width, "Cut width", 0.01, Range::positive(), "cuts: thickness of each cut [m]");
}
}  // namespace

const ParameterTable<BodySettings>& BodySettings::table() {
  static const ParameterTable<BodySettings> t = [] {
    ParameterTable<BodySettings> table;
    using B = BodySettings;
    add_shape_parameters(table, {{"box", ShapeKind::box},
                                 {"sphere", ShapeKind::sphere},
                                 {"cylinder", ShapeKind::cylinder},
                                 {"half_space", ShapeKind::half_space},
                                 {"mesh", ShapeKind::mesh}});
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
    add_shape_parameters(table, {{"box", ShapeKind::box},
                                 {"sphere", ShapeKind::sphere},
                                 {"cylinder", ShapeKind::cylinder},
                                 {"half_space", ShapeKind::half_space},
                                 {"mesh", ShapeKind::mesh}});
    table.choice(&C::contact, "Contact", boundary::ContactType::sticky, contact_words,
                 "sticky: nodes inside move with the solid (Dirichlet grips); slip: normal only; separating: slip while approaching")
        .vector3(&C::velocity, "Velocity", Vec3::Zero(), "kinematic velocity [m/s]")
        .real(&C::start_time, "Start time", 0.0, Range::non_negative(), "time the solid starts moving [s]")
        .real(&C::stop_time, "Stop time", 1e30, Range::non_negative(),
              "time the solid stops moving [s] (not before Start time)")
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
    add_shape_parameters(table, {{"disc", ShapeKind::disc}, {"box", ShapeKind::box}, {"cylinder", ShapeKind::cylinder}});
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
    add_shape_parameters(table, {{"box", ShapeKind::box},
                                 {"sphere", ShapeKind::sphere},
                                 {"cylinder", ShapeKind::cylinder},
                                 {"mesh", ShapeKind::mesh},
                                 {"cuts", ShapeKind::cuts}});
    table.string(&R::body, "Body", "", {}, "name of a sublist of Bodies whose particles the region re-assigns")
        .string(&R::material, "Material", "", {}, "name of a sublist of Materials: the particles' new material");
    return table;
  }();
  return t;
}

const ParameterTable<SolverFileSettings>& SolverFileSettings::table() {
  static const ParameterTable<SolverFileSettings> t = [] {
    ParameterTable<SolverFileSettings> table;
    table.string(&SolverFileSettings::file, "File", "", {},
                 "solver XML, relative to the scene file (--solver overrides it); none: the built-in default, "
                 "Belos CG with Ifpack2 Jacobi (inputs/solvers/jacobi_cg.xml)");
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
              "voxels of this size [m], at least 1.5e-5) to DIR/surface_NNNNN.obj and DIR/surface_NNNNN.vdb; 0: none");
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

// ---------------------------------------------------------------------------------------------
// The sections of a scene, each declared once: its name, whether it holds one sublist per item,
// its parameters and how it is read.
namespace {
struct Reading {
  const std::string& file;
  SceneConfig& scene;
};

struct Section {
  const char* name;
  bool per_item;  ///< one sublist per item (Bodies/<name>/...)
  /// The parameters of the section (of `item`, its sublist, for model-dependent materials).
  std::vector<ParameterSpec> (*specs)(const Teuchos::ParameterList* item);
  /// Reads the section, or one item (`name`) of it, at `path`.
  void (*read)(const Teuchos::ParameterList& list, const std::string& name, const std::string& path, Reading& r);
};

template <class Settings>
std::vector<ParameterSpec> specs_of(const Teuchos::ParameterList*) {
  return Settings::table().specs();
}

template <class Settings>
Settings parse(const Teuchos::ParameterList& list, const std::string& path, const std::string& file) {
  return Settings::table().parse(read_parameters(list, Settings::table().specs(), file, path));
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

// "Model" and, once it names a model, that model's parameters.
std::vector<ParameterSpec> material_specs(const Teuchos::ParameterList* item) {
  std::vector<ParameterSpec> specs = {model_spec()};
  const std::string* model = item != nullptr ? item->getPtr<std::string>("Model") : nullptr;
  if (model != nullptr)
    if (const auto* entry = materials::find_model(*model))
      specs.insert(specs.end(), entry->parameters.begin(), entry->parameters.end());
  return specs;
}

void read_material(const Teuchos::ParameterList& list, const std::string& name, const std::string& path, Reading& r) {
  if (!list.isParameter("Model"))
    throw parameter_error(r.file, path + "/Model", "missing (one of the registered models)");
  Teuchos::ParameterList model_only;  // the model first: it decides the other parameters
  model_only.setEntry("Model", list.getEntry("Model"));
  (void)read_parameters(model_only, {model_spec()}, r.file, path);
  ParameterValues values = read_parameters(list, material_specs(&list), r.file, path);
  const materials::ModelEntry* entry = materials::find_model(values.string("Model"));
  if (entry->check)
    if (const auto problem = entry->check(values))
      throw parameter_error(r.file, path + "/" + problem->parameter, problem->reason);
  r.scene.materials.push_back({name, entry->model, entry, std::move(values)});
}

void read_solver(const Teuchos::ParameterList& list, const std::string&, const std::string& path, Reading& r) {
  const auto solver = parse<SolverFileSettings>(list, path, r.file);
  if (solver.file.empty()) return;  // the built-in default
  const std::filesystem::path solver_path(solver.file);
  r.scene.solver_file = solver_path.is_absolute()
                            ? solver_path.string()
                            : (std::filesystem::path(r.file).parent_path() / solver_path).lexically_normal().string();
  if (!std::filesystem::is_regular_file(r.scene.solver_file))
    throw parameter_error(r.file, "Solver/File", "cannot open '" + r.scene.solver_file + "'");
}

const std::vector<Section>& sections() {
  static const std::vector<Section> list = {
      {"Simulation", false, specs_of<SimulationSettings>,
       [](const auto& l, const auto&, const auto& path, Reading& r) { r.scene.simulation = parse<SimulationSettings>(l, path, r.file); }},
      {"Grid", false, specs_of<GridSettings>,
       [](const auto& l, const auto&, const auto& path, Reading& r) { r.scene.grid = parse<GridSettings>(l, path, r.file); }},
      {"Newton", false, specs_of<newton::NewtonSettings>,
       [](const auto& l, const auto&, const auto& path, Reading& r) { r.scene.newton = parse<newton::NewtonSettings>(l, path, r.file); }},
      {"Solver", false, specs_of<SolverFileSettings>, read_solver},
      {"Output", false, specs_of<OutputSettings>,
       [](const auto& l, const auto&, const auto& path, Reading& r) { r.scene.output = parse<OutputSettings>(l, path, r.file); }},
      {"Materials", true, material_specs, read_material},
      {"Bodies", true, specs_of<BodySettings>,
       [](const auto& l, const auto& name, const auto& path, Reading& r) {
         r.scene.bodies.push_back(parse<BodySettings>(l, path, r.file));
         r.scene.bodies.back().name = name;
       }},
      {"Colliders", true, specs_of<ColliderSettings>,
       [](const auto& l, const auto& name, const auto& path, Reading& r) {
         r.scene.colliders.push_back(parse<ColliderSettings>(l, path, r.file));
         r.scene.colliders.back().name = name;
       }},
      {"Emitters", true, specs_of<EmitterSettings>,
       [](const auto& l, const auto& name, const auto& path, Reading& r) {
         r.scene.emitters.push_back(parse<EmitterSettings>(l, path, r.file));
         r.scene.emitters.back().name = name;
       }},
      {"Regions", true, specs_of<RegionSettings>,
       [](const auto& l, const auto& name, const auto& path, Reading& r) {
         r.scene.regions.push_back(parse<RegionSettings>(l, path, r.file));
         r.scene.regions.back().name = name;
       }},
  };
  return list;
}

const Section* find_section(const std::string& name) {
  for (const auto& s : sections())
    if (name == s.name) return &s;
  return nullptr;
}

// Reads one section of `root` (an absent section: its defaults, or no items).
void read_section(const Teuchos::ParameterList& root, const Section& section, Reading& r) {
  const Teuchos::ParameterList empty;
  const Teuchos::ParameterList& list = root.isSublist(section.name) ? root.sublist(section.name) : empty;
  if (!section.per_item) {
    section.read(list, section.name, section.name, r);
    return;
  }
  for (auto it = list.begin(); it != list.end(); ++it) {
    const std::string path = std::string(section.name) + "/" + list.name(it);
    if (!list.entry(it).isList()) throw parameter_error(r.file, path, "expected a sublist (one per item)");
    section.read(Teuchos::getValue<Teuchos::ParameterList>(list.entry(it)), list.name(it), path, r);
  }
}

std::vector<std::string> split_path(const std::string& path) {
  std::vector<std::string> parts;
  std::stringstream in(path);
  for (std::string part; std::getline(in, part, '/');)
    if (!part.empty()) parts.push_back(part);
  return parts;
}

void apply_override(Teuchos::ParameterList& root, const Override& o, const std::string& file) {
  const auto parts = split_path(o.path);
  const Section* section = parts.empty() ? nullptr : find_section(parts[0]);
  const std::size_t depth = section != nullptr && section->per_item ? 3 : 2;
  std::vector<ParameterSpec> specs;
  if (section != nullptr && parts.size() == depth) {
    const Teuchos::ParameterList* item = nullptr;
    if (depth == 3 && root.isSublist(parts[0]) && root.sublist(parts[0]).isSublist(parts[1]))
      item = &root.sublist(parts[0]).sublist(parts[1]);
    specs = section->specs(item);
  }
  const auto spec = std::find_if(specs.begin(), specs.end(), [&](const auto& s) { return s.name == parts.back(); });
  if (spec == specs.end()) throw InputError(file + ": --set '" + o.path + "': unknown parameter");
  Teuchos::ParameterList* target = &root;
  for (std::size_t k = 0; k + 1 < parts.size(); ++k) target = &target->sublist(parts[k]);
  try {
    set_entry(*target, parts.back(), parse_value(*spec, o.value));
  } catch (const InputError& e) {
    throw InputError(file + ": --set '" + o.path + "': " + e.what());
  }
}
}  // namespace

// ---------------------------------------------------------------------------------------------
// Names to indices.
namespace {
int material_index(const SceneConfig& scene, const std::string& name, const std::string& path) {
  for (std::size_t m = 0; m < scene.materials.size(); ++m)
    if (scene.materials[m].name == name) return static_cast<int>(m);
  throw parameter_error(scene.file, path, "no material named '" + name + "'");
}
}  // namespace

void link_names(SceneConfig& scene) {
  for (auto& m : scene.materials) {
    m.entry = materials::find_model(m.model);
    if (m.entry == nullptr) throw parameter_error(scene.file, "Materials/" + m.name + "/Model", "unknown model '" + m.model + "'");
  }
  for (auto& b : scene.bodies) b.material_id = material_index(scene, b.material, "Bodies/" + b.name + "/Material");
  for (auto& e : scene.emitters) e.material_id = material_index(scene, e.material, "Emitters/" + e.name + "/Material");
  for (auto& r : scene.regions) {
    const std::string path = "Regions/" + r.name;
    r.material_id = material_index(scene, r.material, path + "/Material");
    r.body_id = -1;
    for (std::size_t b = 0; b < scene.bodies.size(); ++b)
      if (scene.bodies[b].name == r.body) r.body_id = static_cast<int>(b);
    if (r.body_id < 0) throw parameter_error(scene.file, path + "/Body", "no body named '" + r.body + "'");
  }
}

// ---------------------------------------------------------------------------------------------
// Shapes, and what is derived from Grid/Cell size once every override is applied.
namespace {
Shape::Kind shape_kind(ShapeKind kind) {
  switch (kind) {
    case ShapeKind::box: return Shape::Kind::box;
    case ShapeKind::sphere: return Shape::Kind::sphere;
    case ShapeKind::cylinder: return Shape::Kind::cylinder;
    case ShapeKind::disc: return Shape::Kind::cylinder;
    case ShapeKind::half_space: return Shape::Kind::half_space;
    case ShapeKind::mesh: return Shape::Kind::mesh;
    case ShapeKind::cuts: return Shape::Kind::cuts;
  }
  return Shape::Kind::box;
}

Shape make_shape(const ShapeSettings& s, const std::string& file, const std::string& path) {
  Shape shape;
  shape.kind = shape_kind(s.shape);
  shape.lower = s.lower_corner;
  shape.upper = s.upper_corner;
  shape.center = s.center;
  shape.radius = s.radius;
  shape.length = s.length;
  shape.field = s.field;
  shape.cut_count = s.cut_count;
  shape.cut_width = s.cut_width;
  if (shape.kind == Shape::Kind::mesh && !shape.field && !file.empty())
    throw parameter_error(file, path + "/File", "no mesh loaded");
  const Vec3 direction = shape.kind == Shape::Kind::half_space ? s.normal : s.axis;
  if (direction.norm() == 0.0) throw parameter_error(file, path, "direction must be non-zero");
  shape.axis = direction.normalized();
  if (shape.kind == Shape::Kind::box && !(s.upper_corner.array() > s.lower_corner.array()).all())
    throw parameter_error(file, path + "/Upper corner", "must exceed Lower corner in every component");
  return shape;
}

double mesh_area(const geometry::TriangleMesh& mesh) {
  double area = 0.0;
  for (const auto& t : mesh.triangles)
    area += 0.5 * (mesh.vertices[t[1]] - mesh.vertices[t[0]]).cross(mesh.vertices[t[2]] - mesh.vertices[t[0]]).norm();
  return area;
}

// Peak memory of OpenVDB's meshToLevelSet per voxel of its 6-voxel band (measured: 33-35 bytes,
// the toothbrush of inputs/meshes at voxels of 2.5 to 0.625 mm, doc/contracts.md).
constexpr double level_set_bytes_per_voxel = 40.0;
// OpenVDB's voxel coordinates are 32-bit integers.
constexpr double max_voxels_across = 1073741824.0;

// A mesh's level set (of the placed mesh) must be one OpenVDB can build (its smallest voxel, its
// coordinate range) and whose band fits in this machine's memory; the message names the
// parameter that decides (Voxel size, or File for the default quarter cell; Scale or Center for
// the range).
void check_level_set(const geometry::TriangleMesh& mesh, double voxel, const ShapeSettings& s,
                     const std::string& file, const std::string& path) {
  std::ostringstream reason;
  reason.precision(3);
  Vec3 lo, hi;
  mesh.bounding_box(lo, hi);
  const double reach = std::max(lo.cwiseAbs().maxCoeff(), hi.cwiseAbs().maxCoeff()) / voxel;
  const double size = (hi - lo).maxCoeff() / voxel;
  const double bytes = level_set_bytes_per_voxel * 6.0 * mesh_area(mesh) / (voxel * voxel);
  const double memory = parallel::machine_memory();
  std::string parameter = s.voxel_size > 0.0 ? "/Voxel size" : "/File";
  if (voxel < min_voxel_size) {
    reason << "voxels of " << voxel << " m are below the smallest OpenVDB takes (" << min_voxel_size << " m)";
  } else if (reach > max_voxels_across) {
    parameter = size > max_voxels_across ? "/Scale" : "/Center";
    reason << "the placed mesh reaches " << reach << " voxels of " << voxel
           << " m from the origin, more than OpenVDB can index (" << max_voxels_across << ")";
  } else if (bytes > memory) {
    reason << "its level set needs about " << bytes / 1073741824.0 << " GiB (" << level_set_bytes_per_voxel
           << " bytes per voxel of its band), more than the " << memory / 1073741824.0 << " GiB of this machine";
  } else {
    return;
  }
  throw parameter_error(file, path + parameter, reason.str());
}

// Reads the mesh of a mesh shape, places it (Scale, Center) and builds its signed distance field;
// a body or region needs a closed mesh (it has an inside).
void load_mesh(ShapeSettings& s, const std::string& file, const std::string& path, double cell_size,
               bool must_be_closed) {
  if (s.shape != ShapeKind::mesh) return;
  const std::string where = file + ": parameter '" + path + "/File': ";
  if (s.mesh_file.empty()) throw InputError(where + "a mesh shape needs a file");
  const std::filesystem::path mesh_path = std::filesystem::path(s.mesh_file).is_absolute()
                                              ? std::filesystem::path(s.mesh_file)
                                              : std::filesystem::path(file).parent_path() / s.mesh_file;
  const std::string mesh_file = mesh_path.lexically_normal().string();
  geometry::TriangleMesh mesh;
  try {
    mesh = geometry::transformed(geometry::read_mesh(mesh_file), s.mesh_scale, s.center);
  } catch (const InputError& e) {
    throw InputError(where + e.what());
  }
  for (const Vec3& v : mesh.vertices)
    if (!v.allFinite())
      throw InputError(where + mesh_file + ": a vertex placed at Scale·x + Center is not finite (" +
                       number_text(s.mesh_scale) + " · x overflows)");
  if (must_be_closed && !geometry::is_closed(mesh))
    throw InputError(where + mesh_file + ": the mesh is not closed (every edge must join two consistently oriented triangles)");
  const double voxel = s.voxel_size > 0.0 ? s.voxel_size : 0.25 * cell_size;
  check_level_set(mesh, voxel, s, file, path);
  s.field = std::make_shared<geometry::LevelSet>(mesh, voxel);
}

// How the ranks reading a scene together agree on a stop request: given this rank's signal (0:
// none), the largest of all ranks' (collective), or this rank's alone when it reads by itself.
using StopAgreement = std::function<int(int)>;

// One mesh's level set, a stage of reading: a stop request that ended this rank's build (or
// came before its end) is agreed with the other ranks after the stage, so that every rank throws
// StopRequested together or none does — none goes on to a collective the others have left.
// (The checks before the build, which may throw InputError, read the same files on every rank.)
void load_mesh_stage(ShapeSettings& s, const std::string& file, const std::string& path, double cell_size,
                     bool must_be_closed, const StopAgreement& agree) {
  if (s.shape != ShapeKind::mesh) return;
  int signal = 0;
  try {
    load_mesh(s, file, path, cell_size, must_be_closed);
  } catch (const StopRequested& e) {
    signal = e.signal;
  }
  if (const int agreed = agree(std::max(signal, stop_signal()))) throw StopRequested(agreed);
}

// Meshes' level sets (voxels default to a quarter cell) and disc nozzles (two cells along the
// velocity): after every override, so that a changed cell size reaches them.
void derive_from_cell_size(SceneConfig& scene, const StopAgreement& agree) {
  const double dx = scene.grid.cell_size;
  for (auto& b : scene.bodies) load_mesh_stage(b, scene.file, "Bodies/" + b.name, dx, true, agree);
  for (auto& c : scene.colliders) load_mesh_stage(c, scene.file, "Colliders/" + c.name, dx, false, agree);
  for (auto& r : scene.regions) load_mesh_stage(r, scene.file, "Regions/" + r.name, dx, true, agree);
  for (auto& e : scene.emitters)
    if (e.shape == ShapeKind::disc) {
      e.axis = e.velocity;
      e.length = 2.0 * dx;
    }
}
}  // namespace

Shape shape_of(const ShapeSettings& s) { return make_shape(s, "", ""); }

boundary::Collider collider_of(const ColliderSettings& c) {
  boundary::Collider collider;
  collider.name = c.name;
  collider.shape = shape_of(c);
  collider.type = c.contact;
  collider.motion.velocity = c.velocity;
  collider.motion.angular_velocity = c.angular_velocity;
  collider.motion.center = c.rotation_center;
  collider.motion.start_time = c.start_time;
  collider.motion.stop_time = c.stop_time;
  for (std::size_t k = 0; k < c.keyframe_times.size(); ++k) {
    boundary::Keyframe key;
    key.time = c.keyframe_times[k];
    key.position = Vec3(c.keyframe_positions[3 * k], c.keyframe_positions[3 * k + 1], c.keyframe_positions[3 * k + 2]);
    if (!c.keyframe_rotations.empty())
      key.rotation = Vec3(c.keyframe_rotations[3 * k], c.keyframe_rotations[3 * k + 1], c.keyframe_rotations[3 * k + 2]);
    collider.motion.keyframes.push_back(key);
  }
  collider.surface_velocity = c.surface_velocity;
  return collider;
}

// ---------------------------------------------------------------------------------------------
// Cross-parameter checks.
namespace {
// At most 2^53 grid nodes: their ids, and 3 per node for the Newton unknowns, stay exact in the
// 64-bit integers (and doubles) that hold them.
constexpr double max_grid_nodes = 9007199254740992.0;
// Cell indices per dimension are ints.
constexpr double max_cells_per_dimension = 1073741824.0;
// The stiffness of a step next to its inertia: beyond 1/ε (ε the double precision) the particles'
// mass is lost in the round-off of the Hessian, at every Δt the scene allows.
constexpr double max_stiffness_ratio = 1.0 / std::numeric_limits<double>::epsilon();

// Physical bounds that no allowed Δt can resolve (issue 24), each naming its parameter:
// - gravity: in the smallest step gravity alone brings a particle at rest to g·Δt_min, and the
//   CFL condition on that speed asks for Δt ≤ CFL·Δx / (g·Δt_min): beyond g = CFL·Δx / Δt_min² no
//   step can be taken;
// - elasticity: a material's P-wave modulus λ + 2μ against its inertia in one step,
//   (λ + 2μ)·Δt² / (ρ·Δx²) = (c·Δt/Δx)², beyond max_stiffness_ratio at Δt = Min time step;
// - viscosity: the Newtonian term's Hessian, 2·c_N·V/Δx² per node (c_N the coefficient of
//   Φ^N = c_N ε̂:ε̂ V, ε̂ = sym(A)/Δt), against the mass ρ·V: the viscous diffusion number
//   η·Δt/(ρ·Δx²) = ν·Δt/Δx² (η = c_N/Δt whichever the convention), beyond max_stiffness_ratio at
//   Δt = Min time step — the smallest it can be (c_N = Δt·η grows with Δt; the paper's μ^N does
//   not depend on it).
void check_physical_bounds(const SceneConfig& scene) {
  const double dx = scene.grid.cell_size, dt = scene.simulation.min_time_step;
  const double g = scene.simulation.gravity.stableNorm();  // no overflow: 1e300 stays 1e300
  const double g_max = scene.simulation.cfl * dx / (dt * dt);
  if (!(g <= g_max)) {
    std::ostringstream reason;
    reason.precision(3);
    reason << "a gravity of " << g << " m/s^2 moves a particle at rest by more than CFL·Δx in Simulation/Min time step ("
           << dt << " s): no step can be taken above CFL·Δx/Δt_min² = " << g_max << " m/s^2";
    throw parameter_error(scene.file, "Simulation/Gravity", reason.str());
  }
  for (const auto& m : scene.materials) {
    if (!m.entry || !m.values.has("Density") || !m.values.has("Lame lambda") || !m.values.has("Shear modulus")) continue;
    const double density = m.values.real("Density"), mu = m.values.real("Shear modulus"),
                 lambda = m.values.real("Lame lambda");
    const double ratio = (lambda + 2.0 * mu) * dt * dt / (density * dx * dx);
    if (ratio <= max_stiffness_ratio) continue;
    std::ostringstream reason;
    reason.precision(3);
    reason << "(λ + 2μ)·Δt²/(ρ·Δx²) = " << ratio << " at Simulation/Min time step (" << dt
           << " s): the material's stiffness exceeds its inertia in a step by more than double precision holds ("
           << max_stiffness_ratio << "), at every Δt the scene allows";
    throw parameter_error(scene.file, "Materials/" + m.name + (lambda > 2.0 * mu ? "/Lame lambda" : "/Shear modulus"),
                          reason.str());
  }
  for (const auto& m : scene.materials) {
    if (!m.entry || !m.values.has("Density") || !m.values.has("Newtonian viscosity")) continue;
    ParameterTable<materials::NewtonianParameters> newtonian;
    materials::add_newtonian_parameters(newtonian);
    const materials::NewtonianParameters viscous = newtonian.parse(m.values);
    const double c_n = materials::viscous_coefficient(viscous.viscosity_convention, viscous.newtonian_viscosity, dt);
    const double number = c_n / (m.values.real("Density") * dx * dx);
    if (number <= max_stiffness_ratio) continue;
    std::ostringstream reason;
    reason.precision(3);
    reason << "the viscous diffusion number η·Δt/(ρ·Δx²) = " << number << " at Simulation/Min time step (" << dt
           << " s): the material's viscosity exceeds its inertia in a step by more than double precision holds ("
           << max_stiffness_ratio << "), at every Δt the scene allows";
    throw parameter_error(scene.file, "Materials/" + m.name + "/Newtonian viscosity", reason.str());
  }
}

void check_grid_and_time_steps(const SceneConfig& scene) {
  const std::string& file = scene.file;
  const GridSettings& grid = scene.grid;
  if (scene.bodies.empty() && scene.emitters.empty())
    throw parameter_error(file, "Bodies", "the scene has no bodies (and no emitters)");
  if (!(grid.upper_corner.array() > grid.lower_corner.array()).all())
    throw parameter_error(file, "Grid/Upper corner", "must exceed Lower corner in every component");
  const Vec3 extent = grid.upper_corner - grid.lower_corner;
  if (!extent.allFinite()) throw parameter_error(file, "Grid/Upper corner", "the extent of the grid is not finite");
  if (extent.minCoeff() < 2.0 * (grid.wall_thickness + 2) * grid.cell_size)
    throw parameter_error(file, "Grid/Cell size", "the domain must be several cells wide in every direction");
  if (scene.simulation.min_time_step > scene.simulation.max_time_step)
    throw parameter_error(file, "Simulation/Min time step", "exceeds Max time step");
  // Node ids are 64-bit integers and the Newton unknowns 3 per node: bound the grid before any
  // arithmetic in integers (doubles here, so that nothing overflows).
  double nodes = 1.0, widest = 0.0;
  for (int d = 0; d < 3; ++d) {
    nodes *= std::ceil(extent[d] / grid.cell_size) + 1.0;
    widest = std::max(widest, std::ceil(extent[d] / grid.cell_size));
  }
  if (nodes > max_grid_nodes || widest > max_cells_per_dimension) {
    std::ostringstream reason;
    reason << grid.cell_size << " m makes " << nodes << " grid nodes (" << widest
           << " cells across), more than viscompm can number (" << max_grid_nodes << " nodes, "
           << max_cells_per_dimension << " cells across)";
    throw parameter_error(file, "Grid/Cell size", reason.str());
  }
  const double surface_voxel = scene.output.surface_voxel_size;
  if (surface_voxel > 0.0 && surface_voxel < min_voxel_size)
    throw parameter_error(file, "Output/Surface voxel size",
                          "voxels of " + number_text(surface_voxel) + " m are below the smallest OpenVDB takes (" +
                              number_text(min_voxel_size) + " m)");
}

void check_keyframes(const ColliderSettings& c, const std::string& file, const std::string& path) {
  const std::size_t n = c.keyframe_times.size();
  if (n == 0) {
    if (!c.keyframe_positions.empty() || !c.keyframe_rotations.empty())
      throw parameter_error(file, path + "/Keyframe times", "keyframes need their times");
    return;
  }
  for (std::size_t k = 1; k < n; ++k)
    if (!(c.keyframe_times[k] > c.keyframe_times[k - 1]))
      throw parameter_error(file, path + "/Keyframe times", "must increase");
  if (c.keyframe_positions.size() != 3 * n)
    throw parameter_error(file, path + "/Keyframe positions",
                          "needs 3 numbers per keyframe time (" + std::to_string(3 * n) + "), got " +
                              std::to_string(c.keyframe_positions.size()));
  if (!c.keyframe_rotations.empty() && c.keyframe_rotations.size() != 3 * n)
    throw parameter_error(file, path + "/Keyframe rotations",
                          "needs 3 numbers per keyframe time (" + std::to_string(3 * n) + "), got " +
                              std::to_string(c.keyframe_rotations.size()));
}

// The fastest motion a scene prescribes, and the parameter that sets it.
struct FastestMotion : PrescribedMotion {
  void consider(double s, const std::string& path) {
    if (s > speed) {
      speed = s;
      parameter = path;
    }
  }
};

// Half the diagonal of a bounded shape's box (0 for unbounded ones).
double half_diagonal(const Shape& shape) {
  Vec3 lo, hi;
  shape.bounding_box(lo, hi);
  return lo.allFinite() && hi.allFinite() ? 0.5 * (hi - lo).norm() : 0.0;
}

// The parameter of the largest of the terms a speed sums.
std::string dominant(const std::vector<std::pair<double, std::string>>& terms) {
  return std::max_element(terms.begin(), terms.end(), [](const auto& a, const auto& b) { return a.first < b.first; })->second;
}

FastestMotion fastest_motion(const SceneConfig& scene) {
  FastestMotion fastest;
  for (const auto& b : scene.bodies) {
    const double v = b.velocity.norm(), w = b.angular_velocity.norm() * half_diagonal(shape_of(b));
    fastest.consider(v + w, "Bodies/" + b.name + "/" + dominant({{v, "Velocity"}, {w, "Angular velocity"}}));
  }
  for (const auto& c : scene.colliders) {
    const boundary::Collider collider = collider_of(c);
    const double speed = collider.max_speed(), v = c.velocity.norm(), s = c.surface_velocity.norm();
    const std::string parameter = !c.keyframe_times.empty()
                                      ? "Keyframe positions"
                                      : dominant({{v, "Velocity"}, {s, "Surface velocity"}, {speed - v - s, "Angular velocity"}});
    fastest.consider(speed, "Colliders/" + c.name + "/" + parameter);
  }
  for (const auto& e : scene.emitters) fastest.consider(e.velocity.norm(), "Emitters/" + e.name + "/Velocity");
  return fastest;
}

}  // namespace

PrescribedMotion fastest_prescribed_motion(const SceneConfig& scene) { return fastest_motion(scene); }

namespace {
// Δt follows the fastest motion (CFL); below Min time step a run could not take a step.
void check_speeds(const SceneConfig& scene) {
  const PrescribedMotion fastest = fastest_prescribed_motion(scene);
  if (!(fastest.speed > 0.0)) return;
  const double dt = scene.simulation.cfl * scene.grid.cell_size / fastest.speed;
  if (std::isfinite(fastest.speed) && dt >= scene.simulation.min_time_step) return;
  std::ostringstream reason;
  reason.precision(3);
  reason << "a speed of " << fastest.speed << " m/s needs steps of CFL·Δx/speed = " << dt
         << " s, below Simulation/Min time step (" << scene.simulation.min_time_step << " s)";
  throw parameter_error(scene.file, fastest.parameter, reason.str());
}

// The layer of a nozzle: the plane through its centre, normal to the velocity, inside it.
void nozzle_extent(const EmitterSettings& e, Vec3& lo, Vec3& hi) {
  const Shape nozzle = shape_of(e);
  if (e.shape != ShapeKind::disc) {
    nozzle.bounding_box(lo, hi);
    return;
  }
  const Vec3 n = e.velocity.normalized();
  const Vec3 half = e.radius * (Vec3::Ones() - n.cwiseProduct(n)).cwiseMax(0.0).cwiseSqrt();
  lo = e.center - half;
  hi = e.center + half;
}

// What needs no mesh: motions' times and keyframes, bounded bodies, emitters' velocities, times
// and nozzles (inside the grid, off its last cells, where particles are held).
void check_settings(const SceneConfig& scene) {
  const std::string& file = scene.file;
  const double dx = scene.grid.cell_size;
  for (const auto& b : scene.bodies)
    if (b.shape == ShapeKind::half_space) throw parameter_error(file, "Bodies/" + b.name + "/Shape", "a body must be bounded");
  for (const auto& c : scene.colliders) {
    const std::string path = "Colliders/" + c.name;
    check_keyframes(c, file, path);
    if (c.stop_time < c.start_time) throw parameter_error(file, path + "/Stop time", "must not precede Start time");
  }
  for (const auto& e : scene.emitters) {
    const std::string path = "Emitters/" + e.name;
    if (e.velocity.norm() == 0.0) throw parameter_error(file, path + "/Velocity", "must be non-zero");
    if (e.stop_time <= e.start_time) throw parameter_error(file, path + "/Stop time", "must exceed Start time");
    make_shape(e, file, path);
    Vec3 lo, hi;
    nozzle_extent(e, lo, hi);
    const Vec3 inner_lo = scene.grid.lower_corner.array() + dx, inner_hi = scene.grid.upper_corner.array() - dx;
    if ((lo.array() < inner_lo.array()).any() || (hi.array() > inner_hi.array()).any())
      throw parameter_error(file, path + "/Center",
                            "the nozzle reaches outside the grid (its layers must lie at least one cell inside it)");
  }
}

// The shapes (meshes loaded) and the speeds they move at.
void check_shapes_and_speeds(const SceneConfig& scene) {
  for (const auto& b : scene.bodies) make_shape(b, scene.file, "Bodies/" + b.name);
  for (const auto& c : scene.colliders) make_shape(c, scene.file, "Colliders/" + c.name);
  for (const auto& r : scene.regions) make_shape(r, scene.file, "Regions/" + r.name);
  check_speeds(scene);
}
}  // namespace

namespace {
SceneConfig read_scene_in_stages(const std::string& file, const std::vector<Override>& overrides,
                                 const StopAgreement& agree) {
  auto root = read_xml_file(file);
  for (const auto& o : overrides) apply_override(*root, o, file);

  SceneConfig scene;
  scene.file = file;
  scene.name = std::filesystem::path(file).stem().string();
  std::vector<std::string> names;
  for (const auto& s : sections()) names.push_back(s.name);
  check_entries(*root, {}, names, file, "");
  Reading reading{file, scene};
  for (const auto& s : sections()) read_section(*root, s, reading);
  link_names(scene);
  check_grid_and_time_steps(scene);
  check_physical_bounds(scene);
  check_settings(scene);
  derive_from_cell_size(scene, agree);  // meshes: the only part of reading that may take long
  check_shapes_and_speeds(scene);
  return scene;
}
}  // namespace

SceneConfig read_scene(const std::string& file, const std::vector<Override>& overrides) {
  return read_scene_in_stages(file, overrides, [](int signal) { return signal; });
}

SceneConfig read_scene(const std::string& file, const std::vector<Override>& overrides,
                       const parallel::Communicator& comm) {
  const StopAgreement agree = [&comm](int signal) { return static_cast<int>(comm.max(std::int64_t{signal})); };
  SceneConfig scene = read_scene_in_stages(file, overrides, agree);
  // The last stage: a request that came while the scene was read is agreed before the run's
  // first collective.
  if (const int agreed = agree(stop_signal())) throw StopRequested(agreed);
  return scene;
}

linalg::SolverConfiguration solver_configuration(const SceneConfig& scene) {
  if (!scene.solver_file.empty()) return linalg::SolverConfiguration::read(scene.solver_file);
  return linalg::SolverConfiguration::from_xml(default_solver_xml, "built-in default solver (inputs/solvers/jacobi_cg.xml)");
}

std::string describe_scene_parameters() {
  std::ostringstream out;
  auto section = [&](const std::string& title, const std::vector<ParameterSpec>& specs) {
    out << "  " << title << "\n";
    for (const auto& s : specs)
      out << "    " << s.name << " (" << ParameterSpec::type_name(s.type) << ", " << s.range_text() << "): " << s.doc
          << "\n";
  };
  for (const auto& s : sections()) {
    if (std::string(s.name) == "Materials") continue;  // per model, below
    section(std::string(s.name) + (s.per_item ? "/<name>" : ""), s.specs(nullptr));
  }
  for (const auto& m : materials::model_registry())
    section("Materials/<name> with Model = " + m.model + " (" + m.summary + ")", m.parameters);
  return out.str();
}

}  // namespace viscompm::scene
