#include "viscompm/parallel/decomposition.hpp"

#include <algorithm>
#include <limits>
#include <stdexcept>
#include <string>

#include "viscompm/core/error.hpp"

namespace viscompm::parallel {

BlockDecomposition::BlockDecomposition(const grid::GridGeometry& geometry, int ranks)
    : nodes_(geometry.nodes()) {
  // Choose the process grid with the smallest total block surface (fewest shared nodes).
  double best_surface = std::numeric_limits<double>::max();
  for (int px = 1; px <= ranks; ++px) {
    if (ranks % px != 0) continue;
    for (int py = 1; py <= ranks / px; ++py) {
      if ((ranks / px) % py != 0) continue;
      const int pz = ranks / (px * py);
      if (px > nodes_.x() || py > nodes_.y() || pz > nodes_.z()) continue;
      const double bx = double(nodes_.x()) / px, by = double(nodes_.y()) / py,
                   bz = double(nodes_.z()) / pz;
      const double surface = bx * by + by * bz + bx * bz;
      if (surface < best_surface - 1e-9) {
        best_surface = surface;
        process_grid_ = Int3(px, py, pz);
      }
    }
  }
  if (best_surface == std::numeric_limits<double>::max())
    throw InputError("parameter 'Grid/Cell size': a grid of " + std::to_string(nodes_.x()) + "x" +
                     std::to_string(nodes_.y()) + "x" + std::to_string(nodes_.z()) + " nodes cannot be split among " +
                     std::to_string(ranks) + " ranks");
  for (int d = 0; d < 3; ++d) {
    const int p = process_grid_[d];
    cuts_[d].resize(p + 1);
    for (int a = 0; a <= p; ++a)
      cuts_[d][a] = static_cast<int>((static_cast<long long>(nodes_[d]) * a) / p);
  }
}

int BlockDecomposition::slice_of(int d, int node) const {
  const auto& c = cuts_[d];
  node = std::clamp(node, 0, nodes_[d] - 1);
  // First cut strictly greater than node, minus one.
  const auto it = std::upper_bound(c.begin(), c.end(), node);
  return static_cast<int>(it - c.begin()) - 1;
}

int BlockDecomposition::owner_of_node(const Int3& ijk) const {
  const int a = slice_of(0, ijk.x()), b = slice_of(1, ijk.y()), c = slice_of(2, ijk.z());
  return a + process_grid_.x() * (b + process_grid_.y() * c);
}

std::string BlockDecomposition::describe() const {
  return "blocks " + std::to_string(process_grid_.x()) + "x" + std::to_string(process_grid_.y()) + "x" +
         std::to_string(process_grid_.z());
}

}  // namespace viscompm::parallel

#include "viscompm/parallel/communicator.hpp"

namespace viscompm::parallel {

BoxDecomposition::BoxDecomposition(const grid::GridGeometry& geometry, std::vector<Box> boxes)
    : geometry_(geometry), boxes_(std::move(boxes)) {
  if (boxes_.empty()) throw std::invalid_argument("BoxDecomposition: no boxes");
}

int BoxDecomposition::owner_of_node(const Int3& ijk) const {
  const Vec3 x = geometry_.node_position(ijk);
  // Closed boxes, disjoint by construction: a point is in at most one.
  auto contains = [&](const Box& b) { return (x.array() >= b.lower.array()).all() && (x.array() <= b.upper.array()).all(); };
  if (contains(boxes_[last_])) return last_;
  const int n = static_cast<int>(boxes_.size());
  for (int r = 0; r < n; ++r)
    if (contains(boxes_[r])) return last_ = r;
  // Between or beyond the boxes: the nearest one (the lowest rank on a tie; empty boxes never).
  int best = 0;
  double best_distance = std::numeric_limits<double>::infinity();
  for (int r = 0; r < n; ++r) {
    if (!(boxes_[r].lower.array() <= boxes_[r].upper.array()).all()) continue;  // empty
    const double d = (x - x.cwiseMax(boxes_[r].lower).cwiseMin(boxes_[r].upper)).squaredNorm();
    if (d < best_distance) {
      best_distance = d;
      best = r;
    }
  }
  return best;
}

std::string BoxDecomposition::describe() const { return std::to_string(boxes_.size()) + " RCB boxes"; }

double imbalance(const Communicator& comm, std::size_t local_count) {
  const double count = static_cast<double>(local_count);
  const double total = comm.sum(count);
  return total > 0.0 ? comm.max(count) / (total / comm.size()) : 1.0;
}

}  // namespace viscompm::parallel
