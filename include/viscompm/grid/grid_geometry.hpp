// The background grid: a box of cells of size Δx with nodes on their corners. Node (i, j, k) sits
// at origin + Δx (i, j, k) with 0 <= i <= cells.x() and so on.
#pragma once

#include "viscompm/core/types.hpp"

namespace viscompm::grid {

struct GridGeometry {
  Vec3 origin = Vec3::Zero();
  double dx = 1.0;
  Int3 cells = Int3::Ones();

  Int3 nodes() const { return cells + Int3::Ones(); }
  std::int64_t node_count() const {
    const Int3 n = nodes();
    return static_cast<std::int64_t>(n.x()) * n.y() * n.z();
  }
  NodeId node_id(const Int3& ijk) const {
    const Int3 n = nodes();
    return ijk.x() + static_cast<NodeId>(n.x()) * (ijk.y() + static_cast<NodeId>(n.y()) * ijk.z());
  }
  Int3 node_index(NodeId id) const {
    const Int3 n = nodes();
    const NodeId nx = n.x(), ny = n.y();
    return Int3(static_cast<int>(id % nx), static_cast<int>((id / nx) % ny),
                static_cast<int>(id / (nx * ny)));
  }
  Vec3 node_position(const Int3& ijk) const { return origin + dx * ijk.cast<double>(); }
  Vec3 node_position(NodeId id) const { return node_position(node_index(id)); }
  bool contains_node(const Int3& ijk) const {
    return (ijk.array() >= 0).all() && (ijk.array() <= cells.array()).all();
  }
  Vec3 upper_corner() const { return origin + dx * cells.cast<double>(); }
};

}  // namespace viscompm::grid
