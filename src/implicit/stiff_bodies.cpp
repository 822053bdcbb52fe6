#include "viscompm/implicit/stiff_bodies.hpp"

#include <algorithm>
#include <numeric>
#include <unordered_map>

namespace viscompm::implicit {

namespace {
// Cells (by grid id of their stencil base) whose particles are mostly stiff, with the ids of the
// cells among them that are this rank's own.
std::vector<char> stiff_cells(const IncrementalPotential& potential, double elastic_cfl) {
  const grid::GridLayout& layout = potential.layout();
  const auto& particles = potential.particles();
  const double dx = layout.geometry.dx;
  std::vector<char> stiff_material;
  for (const auto& m : potential.materials()) stiff_material.push_back(m->wave_speed() * potential.dt() / dx >= elastic_cfl);
  std::vector<char> stiff(layout.cell_count(), 0);
  for (std::size_t c = 0; c < layout.cell_count(); ++c) {
    double stiff_mass = 0.0, mass = 0.0;
    for (std::size_t p = layout.cell_begin[c]; p < layout.cell_begin[c + 1]; ++p) {
      mass += particles.mass[p];
      if (stiff_material[particles.material_id[p]]) stiff_mass += particles.mass[p];
    }
    stiff[c] = 2.0 * stiff_mass > mass;
  }
  return stiff;
}

// Union-find over indices.
struct DisjointSets {
  explicit DisjointSets(std::size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), 0); }
  std::size_t find(std::size_t i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
  }
  void join(std::size_t a, std::size_t b) {
    a = find(a);
    b = find(b);
    if (a != b) parent[std::max(a, b)] = std::min(a, b);
  }
  std::vector<std::size_t> parent;
};
}  // namespace

StiffBodies find_stiff_bodies(const IncrementalPotential& potential, double elastic_cfl, int max_bodies,
                              const parallel::Communicator& comm) {
  const grid::GridLayout& layout = potential.layout();
  const grid::GridGeometry& geometry = layout.geometry;
  const std::vector<char> stiff = stiff_cells(potential, elastic_cfl);
  // Every rank's own stiff cells on every rank (grid ids, ascending): the bodies are found the
  // same way everywhere, whatever the rank count.
  std::vector<std::int64_t> own;
  for (std::size_t c = 0; c < layout.own_cell_count; ++c)
    if (stiff[c]) own.push_back(static_cast<std::int64_t>(layout.cells[c]));
  std::vector<std::int64_t> cells = comm.all_gather(own);
  std::sort(cells.begin(), cells.end());
  cells.erase(std::unique(cells.begin(), cells.end()), cells.end());
  std::unordered_map<std::int64_t, std::size_t> index;
  index.reserve(cells.size());
  for (std::size_t k = 0; k < cells.size(); ++k) index.emplace(cells[k], k);
  // Bodies: stiff cells joined through shared faces.
  DisjointSets sets(cells.size());
  for (std::size_t k = 0; k < cells.size(); ++k) {
    const Int3 ijk = geometry.node_index(cells[k]);
    for (int axis = 0; axis < 3; ++axis) {
      Int3 next = ijk;
      next[axis] += 1;
      if (next[axis] >= geometry.nodes()[axis]) continue;
      if (const auto it = index.find(geometry.node_id(next)); it != index.end()) sets.join(k, it->second);
    }
  }
  // Bodies numbered by their first cell, the largest max_bodies kept.
  std::unordered_map<std::size_t, int> root_body;
  std::vector<int> body_of_cell(cells.size());
  std::vector<std::size_t> size;
  std::vector<Vec3> sum;
  for (std::size_t k = 0; k < cells.size(); ++k) {
    const auto [it, added] = root_body.emplace(sets.find(k), static_cast<int>(size.size()));
    if (added) {
      size.push_back(0);
      sum.push_back(Vec3::Zero());
    }
    body_of_cell[k] = it->second;
    ++size[it->second];
    sum[it->second] += geometry.node_position(geometry.node_index(cells[k])) + Vec3::Constant(0.5 * geometry.dx);
  }
  std::vector<int> order(size.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return size[a] > size[b]; });
  std::vector<int> kept(size.size(), -1);
  StiffBodies bodies;
  for (std::size_t r = 0; r < order.size() && static_cast<int>(r) < max_bodies; ++r) {
    kept[order[r]] = static_cast<int>(r);
    bodies.centroids.push_back(sum[order[r]] / static_cast<double>(size[order[r]]));
  }
  bodies.count = static_cast<int>(bodies.centroids.size());
  // The local nodes each body's cells reach (own and ghost cells: owned nodes are complete).
  const int K = layout.nodes_per_cell();
  for (std::size_t c = 0; c < layout.cell_count(); ++c) {
    if (!stiff[c]) continue;
    const auto it = index.find(static_cast<std::int64_t>(layout.cells[c]));
    if (it == index.end()) continue;  // a ghost cell that its owner does not find stiff (cannot happen)
    const int body = kept[body_of_cell[it->second]];
    if (body < 0) continue;
    const int* nodes = layout.nodes_of_cell(c);
    for (int k = 0; k < K; ++k) bodies.node_bodies.emplace_back(nodes[k], body);
  }
  std::sort(bodies.node_bodies.begin(), bodies.node_bodies.end());
  bodies.node_bodies.erase(std::unique(bodies.node_bodies.begin(), bodies.node_bodies.end()), bodies.node_bodies.end());
  return bodies;
}

}  // namespace viscompm::implicit
