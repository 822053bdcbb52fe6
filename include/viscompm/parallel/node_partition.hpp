// The grid nodes of the linear system, kept for many steps. The nodes the particles' stencils
// touch are padded by a margin (and further along each cell's particle velocities), so that the
// set stays valid while the particles move: the sparsity pattern of the Hessian, its maps and its
// Import are built once per partition. Each node is owned by the rank of the decomposition that
// contains it; a rank holds its owned nodes (the rows it assembles, owner computes) and the ghost
// nodes within reach of them (the columns of its rows).
//
// Rows are node windows: the columns of node i are the partition's nodes j with
// |j − i|_∞ ≤ R, R = stencil width − 1 (5³ nodes for quadratic B-splines, 7³ cubic), the nodes a
// particle stencil containing i can reach. Nodes without mass get identity rows (NewtonSystem).
#pragma once

#include <cstdint>
#include <vector>

#include "viscompm/core/types.hpp"
#include "viscompm/grid/bspline.hpp"
#include "viscompm/grid/grid_geometry.hpp"
#include "viscompm/parallel/communicator.hpp"
#include "viscompm/parallel/decomposition.hpp"

namespace viscompm::parallel {

/// An occupied cell and how far to pad it, in cells, below and above along each axis.
struct PaddedCell {
  NodeId cell = 0;
  Int3 pad_below = Int3::Zero();
  Int3 pad_above = Int3::Zero();
};

/// A box of grid nodes with a dense int per node (local indices, owners).
class NodeBox {
 public:
  NodeBox() = default;
  NodeBox(const Int3& lower, const Int3& upper_inclusive, int fill);
  bool contains(const Int3& ijk) const {
    return (ijk.array() >= lower_.array()).all() && (ijk.array() < lower_.array() + extent_.array()).all();
  }
  int& at(const Int3& ijk) { return values_[offset(ijk)]; }
  int at(const Int3& ijk) const { return values_[offset(ijk)]; }
  /// The value at ijk, or `outside` when ijk is not in the box.
  int get(const Int3& ijk, int outside) const { return contains(ijk) ? at(ijk) : outside; }
  const Int3& lower() const { return lower_; }
  const Int3& extent() const { return extent_; }

 private:
  std::size_t offset(const Int3& ijk) const {
    const Int3 r = ijk - lower_;
    return static_cast<std::size_t>(r.x()) +
           static_cast<std::size_t>(extent_.x()) * (static_cast<std::size_t>(r.y()) +
                                                    static_cast<std::size_t>(extent_.y()) * r.z());
  }
  Int3 lower_ = Int3::Zero();
  Int3 extent_ = Int3::Zero();
  std::vector<int> values_;
};

class NodePartition {
 public:
  /// Pads `own_cells` (this rank's occupied cells), hands every padded node to its owner and
  /// finds the ghost nodes and the rows. Collective.
  NodePartition(const Communicator& comm, const grid::GridGeometry& geometry, grid::KernelOrder order,
                const Decomposition& decomposition, const std::vector<PaddedCell>& own_cells);

  /// Local nodes by grid id: [0, owned_count()) owned (ascending), then ghosts (by owner, then id).
  const std::vector<NodeId>& nodes() const { return nodes_; }
  std::size_t owned_count() const { return owned_count_; }
  std::size_t local_count() const { return nodes_.size(); }
  /// Index of node i in the linear system (contiguous by rank: owned nodes of rank r follow those
  /// of the ranks before it, in grid-id order), for every local node.
  const std::vector<std::int64_t>& system_ids() const { return system_ids_; }
  /// The rank owning each ghost node (local index − owned_count()).
  const std::vector<int>& ghost_owners() const { return ghost_owners_; }
  std::int64_t global_count() const { return global_count_; }

  /// Local index of node ijk, or −1 if it is not a local node of the partition.
  int local_index(const Int3& ijk) const { return local_index_.get(ijk, -1); }
  /// Owner of node ijk; ijk must lie within reach of an owned node (window radius).
  int owner(const Int3& ijk) const;
  /// Owner of any grid node by the decomposition the partition was built for (valid while that
  /// decomposition lives: a new decomposition means a new partition).
  int grid_owner(const Int3& ijk) const { return decomposition_->owner_of_node(ijk); }

  /// Window radius R: the columns of node i are the nodes j with |j − i|_∞ ≤ R.
  int window_radius() const { return window_radius_; }
  /// Positions in a window: (2R+1)³, x fastest, offset (−R, −R, −R) first.
  int window_size() const { return window_size_; }
  /// Columns of owned node i: local node indices, ascending, [row_begin(i), row_begin(i+1)).
  std::size_t row_begin(std::size_t i) const { return row_begin_[i]; }
  const std::vector<int>& row_columns() const { return row_columns_; }
  /// For owned node i, the position within its row of the column at each window position
  /// (−1 where the window holds no node of the partition): window_size() entries.
  const std::int16_t* window_slots(std::size_t i) const { return window_slots_.data() + i * window_size_; }

  /// True if every node of the stencils of `cells` (grid ids of stencil bases) is a local node.
  bool covers(const std::vector<NodeId>& cells, std::size_t first, std::size_t last) const;
  /// Fills layout-style cell_nodes (stencil_size local indices per cell) for cells[first, last).
  /// Throws std::logic_error if a node is missing.
  void index_cells(const std::vector<NodeId>& cells, std::size_t first, std::size_t last,
                   std::vector<int>& cell_nodes) const;

  const grid::GridGeometry& geometry() const { return geometry_; }
  grid::KernelOrder order() const { return order_; }

 private:
  void find_owned_nodes(const Communicator& comm, const Decomposition& decomposition,
                        const std::vector<PaddedCell>& own_cells);
  void find_ghost_nodes(const Communicator& comm, const Decomposition& decomposition);
  void build_rows();

  grid::GridGeometry geometry_;
  grid::KernelOrder order_;
  const Decomposition* decomposition_;
  int rank_ = 0;
  int window_radius_ = 2;
  int window_size_ = 125;
  std::vector<NodeId> nodes_;
  std::size_t owned_count_ = 0;
  std::vector<std::int64_t> system_ids_;
  std::vector<int> ghost_owners_;
  std::int64_t global_count_ = 0;
  NodeBox local_index_;  // over the owned nodes' bounding box widened by R
  NodeBox owner_;        // same box; empty on one rank
  std::vector<std::size_t> row_begin_;
  std::vector<int> row_columns_;
  std::vector<std::int16_t> window_slots_;
};

}  // namespace viscompm::parallel
