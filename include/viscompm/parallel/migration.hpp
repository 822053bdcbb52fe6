// Particle migration: every particle moves to the rank that owns its cell (the node base + 1 of
// its stencil), carrying every stored quantity.
#pragma once

#include "viscompm/grid/bspline.hpp"
#include "viscompm/parallel/communicator.hpp"
#include "viscompm/parallel/decomposition.hpp"
#include "viscompm/particles/particle_set.hpp"

namespace viscompm::parallel {

/// Rank that owns a particle at x.
int particle_owner(const Decomposition& decomposition, const grid::GridGeometry& geometry,
                   grid::KernelOrder order, const Vec3& x);

/// Moves particles to their owners. Returns the number this rank sent away.
std::size_t migrate_particles(const Communicator& comm, const Decomposition& decomposition,
                              const grid::GridGeometry& geometry, grid::KernelOrder order,
                              particles::ParticleSet& particles);

}  // namespace viscompm::parallel
