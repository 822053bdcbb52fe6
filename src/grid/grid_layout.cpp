#include "viscompm/grid/grid_layout.hpp"

#include <algorithm>
#include <numeric>
#include <sstream>

#include "viscompm/core/error.hpp"

namespace viscompm::grid {

Vec3 GridLayout::interpolate(std::size_t c, std::size_t p, const NodeVectorField& f) const {
  Vec3 sum = Vec3::Zero();
  for_each_stencil_node(*this, c, p, [&](int, int i, double w, const Vec3&) { sum += w * f[i]; });
  return sum;
}

Mat3 GridLayout::gradient(std::size_t c, std::size_t p, const NodeVectorField& f) const {
  Mat3 sum = Mat3::Zero();
  for_each_stencil_node(*this, c, p,
                        [&](int, int i, double, const Vec3& dw) { sum += f[i] * dw.transpose(); });
  return sum;
}

std::vector<NodeId> bin_particles(particles::ParticleSet& particles, GridLayout& layout) {
  const std::size_t n = particles.size();
  const int width = stencil_width(layout.order);
  const GridGeometry& g = layout.geometry;

  // Cell of every particle; a stencil must lie inside the grid.
  std::vector<NodeId> cell_of(n);
  for (std::size_t p = 0; p < n; ++p) {
    const Int3 base = stencil_base(layout.order, (particles.position[p] - g.origin) / g.dx);
    if (!g.contains_node(base) || !g.contains_node(base + Int3::Constant(width - 1))) {
      std::ostringstream msg;
      msg << "particle " << particles.id[p] << " at (" << particles.position[p].transpose()
          << ") left the grid";
      throw SimulationError(msg.str());
    }
    cell_of[p] = g.node_id(base);
  }
  std::vector<std::size_t> order(n);
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return cell_of[a] != cell_of[b] ? cell_of[a] < cell_of[b] : particles.id[a] < particles.id[b];
  });
  particles.permute(order);

  layout.cells.clear();
  layout.cell_begin.clear();
  layout.stencils.resize(n);
  for (std::size_t k = 0; k < n; ++k) {
    const NodeId cell = cell_of[order[k]];
    if (layout.cells.empty() || layout.cells.back() != cell) {
      layout.cells.push_back(cell);
      layout.cell_begin.push_back(k);
    }
    layout.stencils[k] = make_stencil(layout.order, g.origin, g.dx, particles.position[k]);
  }
  layout.cell_begin.push_back(n);

  std::vector<NodeId> touched;
  touched.reserve(layout.cells.size() * stencil_size(layout.order));
  for (const NodeId cell : layout.cells) {
    const Int3 base = g.node_index(cell);
    for (int cz = 0; cz < width; ++cz)
      for (int by = 0; by < width; ++by)
        for (int ax = 0; ax < width; ++ax) touched.push_back(g.node_id(base + Int3(ax, by, cz)));
  }
  std::sort(touched.begin(), touched.end());
  touched.erase(std::unique(touched.begin(), touched.end()), touched.end());
  return touched;
}

void index_cell_nodes(GridLayout& layout) {
  // Sorted (global id, local id) pairs for lookup.
  std::vector<std::pair<NodeId, int>> lookup(layout.nodes.size());
  for (std::size_t i = 0; i < layout.nodes.size(); ++i) lookup[i] = {layout.nodes[i], static_cast<int>(i)};
  std::sort(lookup.begin(), lookup.end());

  const int width = stencil_width(layout.order);
  const int per_cell = layout.nodes_per_cell();
  layout.cell_nodes.resize(layout.cells.size() * per_cell);
  for (std::size_t c = 0; c < layout.cells.size(); ++c) {
    const Int3 base = layout.geometry.node_index(layout.cells[c]);
    int k = 0;
    for (int cz = 0; cz < width; ++cz)
      for (int by = 0; by < width; ++by)
        for (int ax = 0; ax < width; ++ax, ++k) {
          const NodeId id = layout.geometry.node_id(base + Int3(ax, by, cz));
          const auto it = std::lower_bound(lookup.begin(), lookup.end(), std::make_pair(id, -1));
          if (it == lookup.end() || it->first != id)
            throw std::logic_error("index_cell_nodes: a touched node is missing from the layout");
          layout.cell_nodes[c * per_cell + k] = it->second;
        }
  }
}

}  // namespace viscompm::grid
