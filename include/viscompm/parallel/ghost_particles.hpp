// Owner computes: a rank assembles its rows completely, so it needs every particle whose stencil
// touches a node it owns. Those of its neighbours are copied to it each step as ghost particles
// (all their state: their Hessians are evaluated again where they are ghosts).
#pragma once

#include <cstddef>

#include "viscompm/grid/grid_layout.hpp"
#include "viscompm/parallel/communicator.hpp"
#include "viscompm/parallel/node_partition.hpp"
#include "viscompm/particles/particle_set.hpp"

namespace viscompm::parallel {

/// Sends the particles of this rank's cells (layout cells [0, own_cell_count), particles binned)
/// to every other rank owning a node of their stencils, and appends the ghost particles received
/// to `particles`. Returns the number received. Collective.
std::size_t append_ghost_particles(const Communicator& comm, const NodePartition& partition,
                                   const grid::GridLayout& layout, particles::ParticleSet& particles);

}  // namespace viscompm::parallel
