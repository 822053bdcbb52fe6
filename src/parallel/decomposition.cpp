#include "viscompm/parallel/decomposition.hpp"

#include <algorithm>
#include <limits>
#include <stdexcept>

namespace viscompm::parallel {

BlockDecomposition::BlockDecomposition(const grid::GridGeometry& geometry, int ranks)
    : ranks_(ranks), nodes_(geometry.nodes()) {
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
    throw std::invalid_argument("grid too small for the number of ranks");
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

void BlockDecomposition::owned_block(int rank, Int3& lower, Int3& upper) const {
  const int a = rank % process_grid_.x();
  const int b = (rank / process_grid_.x()) % process_grid_.y();
  const int c = rank / (process_grid_.x() * process_grid_.y());
  lower = Int3(cuts_[0][a], cuts_[1][b], cuts_[2][c]);
  upper = Int3(cuts_[0][a + 1], cuts_[1][b + 1], cuts_[2][c + 1]);
}

void BlockDecomposition::set_cuts(int d, std::vector<int> cuts) {
  if (cuts.size() != cuts_[d].size() || cuts.front() != 0 || cuts.back() != nodes_[d] ||
      !std::is_sorted(cuts.begin(), cuts.end()))
    throw std::invalid_argument("invalid decomposition cuts");
  cuts_[d] = std::move(cuts);
}

}  // namespace viscompm::parallel
