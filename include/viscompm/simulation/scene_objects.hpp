// The scene's solids as the physics layer sees them (the scene's names linked to indices,
// scene::link_names): colliders with their rigid motions and
// surface velocities, emitters with their nozzles' inflow, material regions of bodies.
#pragma once

#include <vector>

#include "viscompm/boundary/colliders.hpp"
#include "viscompm/grid/grid_geometry.hpp"
#include "viscompm/materials/material.hpp"
#include "viscompm/particles/emitter.hpp"
#include "viscompm/particles/regions.hpp"
#include "viscompm/scene/scene.hpp"

namespace viscompm::simulation {

std::vector<boundary::Collider> make_colliders(const scene::SceneConfig& scene);
/// The scene's emitters; their ids follow those every body's lattice reserves. Throws
/// InputError if a nozzle holds no particle site.
std::vector<particles::Emitter> make_emitters(const scene::SceneConfig& scene, const grid::GridGeometry& grid,
                                              const materials::MaterialList& materials);
std::vector<boundary::Inflow> make_inflows(const scene::SceneConfig& scene);
/// The regions of body number `body` (the scene's names linked: scene::link_names).
std::vector<particles::MaterialRegion> make_regions(const scene::SceneConfig& scene, int body,
                                                    const materials::MaterialList& materials);

}  // namespace viscompm::simulation
