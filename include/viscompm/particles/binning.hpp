// Particles sorted by cell for one step: a particle's cell is its stencil base node, and all the
// particles of a cell share one stencil of grid nodes (the element of the assembly).
#pragma once

#include <cstddef>

#include "viscompm/grid/grid_layout.hpp"
#include "viscompm/particles/particle_set.hpp"

namespace viscompm::particles {

/// Sorts particles [first, size) by (cell, id) and appends their cells, cell ranges and stencils
/// to `layout` (first = 0 starts a new layout: cells, ranges and stencils are cleared). Throws
/// SimulationError if a particle's stencil leaves the grid.
void bin_particles(ParticleSet& particles, std::size_t first, grid::GridLayout& layout);

}  // namespace viscompm::particles
