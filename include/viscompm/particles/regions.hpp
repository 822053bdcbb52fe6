// Material regions: the particles of a body that lie inside a region (a box, sphere, cylinder,
// closed mesh, or a pattern of thin planar cuts: the prescored crust of §5.6) take another
// material, with that material's density.
#pragma once

#include "viscompm/core/shape.hpp"
#include "viscompm/particles/particle_set.hpp"

namespace viscompm::particles {

struct MaterialRegion {
  Shape shape;
  int material_id = 0;
  double density = 1.0;
};

/// Re-assigns particles [first, particles.size()) inside `region`; returns how many.
std::size_t assign_region(const MaterialRegion& region, std::size_t first, ParticleSet& particles);

}  // namespace viscompm::particles
