// Setting up a run: what a scene asks for, turned into the objects the stepping works on — the
// estimate of memory made before anything is sampled, the materials, the grid, the boundary
// (colliders and walls), the integrator's settings, and the state a run starts from (the bodies
// sampled, or a checkpoint's particles and counters).
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "viscompm/boundary/colliders.hpp"
#include "viscompm/io/checkpoint.hpp"
#include "viscompm/materials/material.hpp"
#include "viscompm/parallel/decomposition.hpp"
#include "viscompm/particles/emitter.hpp"
#include "viscompm/scene/scene.hpp"
#include "viscompm/simulation/time_integrator.hpp"

namespace viscompm::simulation {

/// The state a run advances, and all a checkpoint of it keeps besides the scene.
struct SimulationState {
  particles::ParticleSet particles;  ///< this rank's
  double time = 0.0;
  std::int64_t step = 0;
  int frame = 0;                     ///< the last frame written (or restarted from)
  double time_step_cap = 0.0;        ///< reduced when a step fails, grows per success
  double balanced_imbalance = 1.0;   ///< the particle imbalance right after the last re-partition
  std::unique_ptr<parallel::Decomposition> decomposition;
  std::vector<particles::Emitter> emitters;
  bool restarted = false;

  /// Mass delivered by all emitters so far.
  double emitted_mass() const;
  /// What a checkpoint of this state records (the scene's name, the decomposition's boxes when
  /// re-partitioned, the emitters' layer counts).
  io::RunState record(const std::string& scene_name) const;
};

/// The scene's materials, in its order, from the registry.
materials::MaterialList make_materials(const scene::SceneConfig& scene);
/// Throws InputError naming the parameter when what the scene will hold cannot fit in the memory
/// of the ranks of `comm` — the bodies' particles ('Grid/Cell size'), the particles the emitters
/// add over the run ('Emitters/<name>/Mass rate' or 'Velocity'), the level set of a frame's
/// particle surface ('Output/Surface voxel size'). An estimate made before anything is sampled
/// (collective).
void check_memory(const scene::SceneConfig& scene, const parallel::Communicator& comm);
/// The grid a scene asks for: cells of its size covering [lower, upper] (rounded up).
grid::GridGeometry make_grid(const scene::GridSettings& grid);
/// Colliders, emitters' inflow and domain walls.
boundary::Boundary make_boundary(const scene::SceneConfig& scene);
/// What the time integrator takes from the scene.
IntegratorSettings integrator_settings(const scene::SceneConfig& scene);
/// The state a run starts from (collective): the scene's bodies sampled on the block
/// decomposition of `grid` (ids independent of the rank count) with the emitters' layers due at
/// time 0, or, with `restart_file`, the checkpoint's state migrated to the owners of its
/// particles. InputError if the checkpoint does not fit the scene or no particle lies in the grid.
SimulationState initial_state(const scene::SceneConfig& scene, const grid::GridGeometry& grid, grid::KernelOrder order,
                              const materials::MaterialList& materials, const boundary::Boundary& boundary,
                              const parallel::Communicator& comm, const std::optional<std::string>& restart_file);

}  // namespace viscompm::simulation
