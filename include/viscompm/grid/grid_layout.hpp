// The grid as one step sees it: which nodes this rank holds (owned first, then shared), the
// occupied cells (a cell = the stencil every particle with the same stencil base touches: the
// "element" of the assembly), and each particle's stencil. Particles are sorted by cell.
#pragma once

#include <cstddef>
#include <vector>

#include "viscompm/core/types.hpp"
#include "viscompm/grid/bspline.hpp"
#include "viscompm/grid/grid_geometry.hpp"
#include "viscompm/particles/particle_set.hpp"

namespace viscompm::grid {

struct GridLayout {
  KernelOrder order = KernelOrder::quadratic;
  GridGeometry geometry;

  /// Local nodes by global id: [0, owned_count) owned by this rank, then shared ones.
  std::vector<NodeId> nodes;
  std::size_t owned_count = 0;

  /// Occupied cells: global id of the stencil base node, ascending.
  std::vector<NodeId> cells;
  /// Particles of cell c are [cell_begin[c], cell_begin[c + 1]).
  std::vector<std::size_t> cell_begin;
  /// Local node index of the stencil nodes of every cell (stencil_size per cell, a fastest).
  std::vector<int> cell_nodes;
  /// Stencil of every particle.
  std::vector<Stencil> stencils;

  int nodes_per_cell() const { return stencil_size(order); }
  std::size_t cell_count() const { return cells.size(); }
  std::size_t local_node_count() const { return nodes.size(); }
  const int* nodes_of_cell(std::size_t c) const { return cell_nodes.data() + c * nodes_per_cell(); }

  /// Σ_i f_i w_ip for particle p of cell c.
  Vec3 interpolate(std::size_t c, std::size_t p, const NodeVectorField& f) const;
  /// Σ_i f_i (∇w_ip)^T for particle p of cell c.
  Mat3 gradient(std::size_t c, std::size_t p, const NodeVectorField& f) const;
};

/// Sorts particles by (cell, id), fills stencils, cells and cell_begin, and returns the sorted
/// global ids of every node the particles touch. Throws SimulationError if a particle's stencil
/// leaves the grid.
std::vector<NodeId> bin_particles(particles::ParticleSet& particles, GridLayout& layout);

/// Fills cell_nodes from `nodes` (which must contain every touched node).
void index_cell_nodes(GridLayout& layout);

/// Calls f(k, node_lid, w, grad_w) for the stencil nodes of particle p in cell c.
template <class F>
void for_each_stencil_node(const GridLayout& layout, std::size_t c, std::size_t p, F&& f) {
  const Stencil& s = layout.stencils[p];
  const int width = stencil_width(layout.order);
  const int* lids = layout.nodes_of_cell(c);
  int k = 0;
  for (int cz = 0; cz < width; ++cz)
    for (int by = 0; by < width; ++by)
      for (int ax = 0; ax < width; ++ax, ++k) f(k, lids[k], s.w(ax, by, cz), s.grad_w(ax, by, cz));
}

}  // namespace viscompm::grid
