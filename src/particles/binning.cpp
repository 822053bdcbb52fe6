#include "viscompm/particles/binning.hpp"

#include <algorithm>
#include <numeric>
#include <sstream>

#include "viscompm/core/error.hpp"

namespace viscompm::particles {

void bin_particles(ParticleSet& particles, std::size_t first, grid::GridLayout& layout) {
  const std::size_t n = particles.size();
  const int width = grid::stencil_width(layout.order);
  const grid::GridGeometry& g = layout.geometry;
  if (first == 0) {
    layout.cells.clear();
    layout.cell_begin.assign(1, 0);
    layout.stencils.clear();
  }

  // Cell of every particle; a stencil must lie inside the grid.
  std::vector<NodeId> cell_of(n);
  for (std::size_t p = first; p < n; ++p) {
    const Int3 base = grid::stencil_base(layout.order, (particles.position[p] - g.origin) / g.dx);
    if (!g.contains_node(base) || !g.contains_node(base + Int3::Constant(width - 1))) {
      std::ostringstream msg;
      msg << "particle " << particles.id[p] << " at (" << particles.position[p].transpose() << ") left the grid";
      throw SimulationError(msg.str());
    }
    cell_of[p] = g.node_id(base);
  }
  std::vector<std::size_t> order(n);
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin() + first, order.end(), [&](std::size_t a, std::size_t b) {
    return cell_of[a] != cell_of[b] ? cell_of[a] < cell_of[b] : particles.id[a] < particles.id[b];
  });
  particles.permute(order);

  layout.stencils.resize(n);
  layout.cell_begin.pop_back();  // the end sentinel, pushed again below
  const std::size_t first_cell = layout.cells.size();
  for (std::size_t k = first; k < n; ++k) {
    const NodeId cell = cell_of[order[k]];
    if (layout.cells.size() == first_cell || layout.cells.back() != cell) {
      layout.cells.push_back(cell);
      layout.cell_begin.push_back(k);
    }
    layout.stencils[k] = grid::make_stencil(layout.order, g.origin, g.dx, particles.position[k]);
  }
  layout.cell_begin.push_back(n);
}

}  // namespace viscompm::particles
