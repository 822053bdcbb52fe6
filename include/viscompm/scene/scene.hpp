// A scene: a Teuchos XML parameter list (inputs/scenes/*.xml) read into typed structs. Every
// parameter is declared once (the tables in scene.cpp and each material model's own table);
// unknown names, wrong types and out-of-range values fail at read time with InputError. Words
// (kernel, transfer, contact, shape, walls, ...) become enums and names (materials, bodies,
// models) indices when the file is read: nothing below scene/ compares configuration words.
//
//   Simulation  frames, frame rate, CFL, Δt bounds, gravity, transfer, kernel
//   Grid        box, cell size, domain walls
//   Newton      newton::NewtonSettings
//   Solver      the solver XML file (none: the built-in default, inputs/solvers/jacobi_cg.xml)
//   Materials   one sublist per material: "Model" and that model's parameters
//   Bodies      one sublist per body: shape, material, sampling, initial velocity
//   Colliders   one sublist per collider: shape, contact type, motion (translation, rotation,
//               keyframes), surface velocity
//   Emitters    one sublist per emitter: nozzle shape, material, velocity, mass rate, times
//   Regions     one sublist per material region: body, material, shape
//   Output      directory, checkpoints, MatrixMarket dumps, surfaces
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "viscompm/boundary/colliders.hpp"
#include "viscompm/core/parameters.hpp"
#include "viscompm/core/shape.hpp"
#include "viscompm/grid/bspline.hpp"
#include "viscompm/linalg/linear_solver.hpp"
#include "viscompm/materials/registry.hpp"
#include "viscompm/newton/newton_settings.hpp"
#include "viscompm/parallel/communicator.hpp"
#include "viscompm/transfer/transfer.hpp"

namespace viscompm::scene {

struct SimulationSettings {
  int frames = 24;
  double frame_rate = 24.0;
  double cfl = 0.5;
  double max_time_step = 1e-2;
  double min_time_step = 1e-7;
  double time_step_growth = 1.5;     ///< the Δt cap grows by this factor per successful step
  double time_step_reduction = 0.5;  ///< Δt of a failed step is multiplied by this before the retry
  Vec3 gravity = Vec3(0.0, -9.81, 0.0);
  transfer::Scheme transfer = transfer::Scheme::apic;
  double flip_ratio = 0.95;
  grid::KernelOrder kernel = grid::KernelOrder::quadratic;
  static const ParameterTable<SimulationSettings>& table();
};

/// What happens to particles that reach the last cell of the grid.
enum class OutsideParticles { clamp, remove };

struct GridSettings {
  Vec3 lower_corner = Vec3::Zero();
  Vec3 upper_corner = Vec3::Ones();
  double cell_size = 0.05;
  boundary::ContactType walls = boundary::ContactType::separating;
  int wall_thickness = 2;
  OutsideParticles outside_particles = OutsideParticles::clamp;
  double rebalance_threshold = 1.25;
  int padding_cells = 0;
  double padding_lookahead = 8.0;
  static const ParameterTable<GridSettings>& table();
};

/// The solids a scene names; a disc (emitters) is a cylinder along the emitter's velocity, two
/// cells long.
enum class ShapeKind { box, sphere, cylinder, half_space, mesh, cuts, disc };

/// The shape parameters bodies and colliders share.
struct ShapeSettings {
  ShapeKind shape = ShapeKind::box;
  Vec3 lower_corner = Vec3::Zero();
  Vec3 upper_corner = Vec3::Ones();
  Vec3 center = Vec3::Zero();
  double radius = 0.1;
  Vec3 axis = Vec3::UnitY();
  double length = 1.0;
  Vec3 normal = Vec3::UnitY();
  std::string mesh_file;           ///< mesh: OBJ or STL, resolved against the scene file
  double mesh_scale = 1.0;         ///< mesh: x ↦ scale·x + Center
  double voxel_size = 0.0;         ///< mesh: level-set voxel [m] (0: a quarter of the cell size)
  int cut_count = 4;               ///< cuts
  double cut_width = 0.01;         ///< cuts
  std::shared_ptr<const DistanceField> field;  ///< mesh: loaded and placed by read_scene
};

struct BodySettings : ShapeSettings {
  std::string name;
  std::string material;
  int material_id = -1;            ///< index into SceneConfig::materials (link_names)
  int particles_per_cell = 2;
  Vec3 velocity = Vec3::Zero();
  Vec3 angular_velocity = Vec3::Zero();
  static const ParameterTable<BodySettings>& table();
};

struct ColliderSettings : ShapeSettings {
  std::string name;
  boundary::ContactType contact = boundary::ContactType::sticky;
  Vec3 velocity = Vec3::Zero();
  double start_time = 0.0;
  double stop_time = 1e30;
  Vec3 angular_velocity = Vec3::Zero();
  Vec3 rotation_center = Vec3::Zero();
  RealList keyframe_times, keyframe_positions, keyframe_rotations;
  Vec3 surface_velocity = Vec3::Zero();
  static const ParameterTable<ColliderSettings>& table();
};

struct EmitterSettings : ShapeSettings {
  std::string name;
  std::string material;
  int material_id = -1;            ///< index into SceneConfig::materials (link_names)
  Vec3 velocity = Vec3::UnitX();
  double mass_rate = 0.0;
  double start_time = 0.0;
  double stop_time = 1e30;
  int particles_per_cell = 2;
  static const ParameterTable<EmitterSettings>& table();
};

struct RegionSettings : ShapeSettings {
  std::string name;
  std::string body;
  int body_id = -1;                ///< index into SceneConfig::bodies (link_names)
  std::string material;
  int material_id = -1;            ///< index into SceneConfig::materials (link_names)
  static const ParameterTable<RegionSettings>& table();
};

struct SolverFileSettings {
  std::string file;  ///< empty: the built-in default solver
  static const ParameterTable<SolverFileSettings>& table();
};

struct OutputSettings {
  std::string directory = "output";
  RealList matrix_market_steps;  ///< steps whose first Newton system is written to MatrixMarket
  int checkpoint_every = 0;      ///< frames between checkpoints (0: none)
  double surface_voxel_size = 0.0;  ///< > 0: each frame's particle surface (OpenVDB) as OBJ and VDB
  double checkpoint_wall_seconds = 0.0;  ///< wall-clock seconds between checkpoints inside frames (0: none)
  static const ParameterTable<OutputSettings>& table();
};

struct MaterialSettings {
  std::string name;
  std::string model;                          ///< the registry's name of the model
  const materials::ModelEntry* entry = nullptr;  ///< the model in the registry (link_names)
  ParameterValues values;  ///< validated against the model's declarations
};

struct SceneConfig {
  std::string file;                  ///< where it was read from
  std::string name;                  ///< the top-level list's name
  SimulationSettings simulation;
  GridSettings grid;
  newton::NewtonSettings newton;
  std::string solver_file;           ///< resolved path; empty: the built-in default solver
  OutputSettings output;
  std::vector<MaterialSettings> materials;
  std::vector<BodySettings> bodies;
  std::vector<ColliderSettings> colliders;
  std::vector<EmitterSettings> emitters;
  std::vector<RegionSettings> regions;
};

/// The solid described by shape parameters (already validated by read_scene).
Shape shape_of(const ShapeSettings& settings);
/// The collider a scene describes: its shape, contact, rigid motion and surface velocity.
boundary::Collider collider_of(const ColliderSettings& settings);

/// The fastest motion a scene prescribes — a body's initial velocity and rotation, a collider's
/// translation, rotation at its farthest point, keyframes and surface velocity, an emitter's
/// velocity — and the parameter that sets it ("Colliders/<name>/Angular velocity"); speed 0 if none.
struct PrescribedMotion {
  double speed = 0.0;  ///< [m/s]
  std::string parameter;
};
PrescribedMotion fastest_prescribed_motion(const SceneConfig& scene);

/// A --set override: "Path/To/Parameter=value".
struct Override {
  std::string path;
  std::string value;
  static Override parse(const std::string& text);
};

/// Reads and validates a scene; overrides are applied first (in order), and every value derived
/// from others (mesh voxels and disc nozzles from Grid/Cell size) is computed after them. Throws
/// InputError.
SceneConfig read_scene(const std::string& file, const std::vector<Override>& overrides = {});
/// The same, read by every rank of `comm` together (the programs), in stages: each mesh's level
/// set — the part of reading that may take long, which a stop request (core/stop_request.hpp)
/// ends on the rank that receives it — is followed by the ranks' agreement on a stop request,
/// and so is the end of reading. A request that reaches only some ranks thus ends reading with
/// StopRequested on every rank at the same stage: none is left waiting at a collective.
SceneConfig read_scene(const std::string& file, const std::vector<Override>& overrides,
                       const parallel::Communicator& comm);

/// Resolves the names a scene refers to — material names of bodies, emitters and regions, the
/// bodies of regions, the models of materials — to indices and registry entries (read_scene does
/// this; scenes built in code call it, or Simulation does). InputError naming the parameter.
void link_names(SceneConfig& scene);

/// The scene's solver configuration: its Solver/File, or the built-in default (the text of
/// inputs/solvers/jacobi_cg.xml, compiled in) when the scene has none.
linalg::SolverConfiguration solver_configuration(const SceneConfig& scene);

/// Documentation of every scene parameter (for --help and doc/).
std::string describe_scene_parameters();

}  // namespace viscompm::scene
