// Filling a solid with particles: a lattice of spacing Δx/n aligned with the grid (n particles
// per cell and dimension), cut by the shape and by the grid (a site outside the grid would be
// clamped onto its faces). Ids come from the lattice index, so they do not
// depend on the number of ranks; each rank keeps the particles it owns.
#pragma once

#include <functional>

#include "viscompm/core/shape.hpp"
#include "viscompm/grid/grid_geometry.hpp"
#include "viscompm/particles/particle_set.hpp"

namespace viscompm::particles {

struct BodySampling {
  Shape shape;
  int particles_per_cell = 2;   ///< per dimension
  double density = 1.0;
  Vec3 velocity = Vec3::Zero();
  Vec3 angular_velocity = Vec3::Zero();  ///< about the shape's bounding-box centre
  int material_id = 0;
};

/// Number of lattice sites of a body's bounding box inside the grid (the id range it reserves).
std::int64_t lattice_size(const BodySampling& body, const grid::GridGeometry& grid);

/// Appends the particles of `body` for which keep(x) is true, with ids id_offset + lattice index.
/// Returns the number of particles added.
std::size_t sample_body(const BodySampling& body, const grid::GridGeometry& grid,
                        ParticleId id_offset, const std::function<bool(const Vec3&)>& keep,
                        ParticleSet& particles);

}  // namespace viscompm::particles
