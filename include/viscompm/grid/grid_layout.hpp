// The grid as one step sees it: the local nodes (owned by this rank first, then ghost nodes owned
// by neighbours), the occupied cells (a cell = the stencil shared by every particle with the same
// stencil base: the "element" of the assembly) and each particle's stencil. Cells of this rank's
// particles come first, then cells of ghost particles (copies of neighbours' particles whose
// stencils reach owned nodes), each part sorted by grid id; particles are sorted the same way.
#pragma once

#include <cstddef>
#include <vector>

#include "viscompm/core/types.hpp"
#include "viscompm/grid/bspline.hpp"
#include "viscompm/grid/grid_geometry.hpp"

namespace viscompm::grid {

struct GridLayout {
  KernelOrder order = KernelOrder::quadratic;
  GridGeometry geometry;

  /// Local nodes by grid id: [0, owned_count) owned by this rank (ascending), then ghost nodes.
  std::vector<NodeId> nodes;
  std::size_t owned_count = 0;

  /// Occupied cells: grid id of the stencil base node; [0, own_cell_count) hold this rank's
  /// particles, the rest ghost particles.
  std::vector<NodeId> cells;
  std::size_t own_cell_count = 0;
  /// Particles of cell c are [cell_begin[c], cell_begin[c + 1]).
  std::vector<std::size_t> cell_begin{0};
  /// Local node index of the stencil nodes of every cell (stencil_size per cell, x fastest).
  std::vector<int> cell_nodes;
  /// Stencil of every particle (own and ghost).
  std::vector<Stencil> stencils;

  int nodes_per_cell() const { return stencil_size(order); }
  std::size_t cell_count() const { return cells.size(); }
  std::size_t local_node_count() const { return nodes.size(); }
  /// Particles [0, own_particle_count()) are this rank's; the rest are ghost copies.
  std::size_t own_particle_count() const { return cell_begin[own_cell_count]; }
  const int* nodes_of_cell(std::size_t c) const { return cell_nodes.data() + c * nodes_per_cell(); }
  bool is_owned(int local_node) const { return static_cast<std::size_t>(local_node) < owned_count; }

  /// Σ_i f_i (∇w_ip)^T for particle p of cell c.
  Mat3 gradient(std::size_t c, std::size_t p, const NodeVectorField& f) const;
};

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
