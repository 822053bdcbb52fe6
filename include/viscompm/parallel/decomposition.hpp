// Ownership of grid nodes by ranks in spatial blocks: the node index range of each dimension is
// cut into pieces, and rank (a, b, c) of the process grid owns the block of nodes between its cuts.
// A particle lives on the rank that owns its cell, the node base + 1 of its stencil.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "viscompm/grid/bspline.hpp"
#include "viscompm/grid/grid_geometry.hpp"

namespace viscompm::parallel {

/// Which rank owns each grid node (and so each particle: the owner of its cell).
class Decomposition {
 public:
  virtual ~Decomposition() = default;
  /// Rank owning node ijk.
  virtual int owner_of_node(const Int3& ijk) const = 0;
  /// Rank owning a particle whose stencil starts at `stencil_base`.
  int owner_of_cell(const Int3& stencil_base) const { return owner_of_node(stencil_base + Int3::Ones()); }
  /// One line for the log.
  virtual std::string describe() const = 0;
};

class BlockDecomposition : public Decomposition {
 public:
  /// Splits the nodes of `geometry` among `ranks` ranks: the process grid is the factorisation of
  /// `ranks` into three factors with the smallest block surface, and cuts are even.
  BlockDecomposition(const grid::GridGeometry& geometry, int ranks);

  /// Rank owning node ijk (clamped to the grid).
  int owner_of_node(const Int3& ijk) const override;
  std::string describe() const override;

 private:
  int slice_of(int d, int node) const;

  Int3 nodes_;
  Int3 process_grid_;
  std::array<std::vector<int>, 3> cuts_;
};

}  // namespace viscompm::parallel

namespace viscompm::parallel {

/// Ownership by disjoint boxes in space, one per rank (box r belongs to rank r): a node belongs
/// to the closed box that contains its position, else to the nearest box (lowest rank on a tie;
/// empty boxes own nothing). Boxes come from a recursive coordinate bisection of
/// the particles (linalg::make_rcb_decomposition, Zoltan2) and are stored in checkpoints.
class BoxDecomposition : public Decomposition {
 public:
  struct Box {
    Vec3 lower, upper;
  };
  BoxDecomposition(const grid::GridGeometry& geometry, std::vector<Box> boxes);

  int owner_of_node(const Int3& ijk) const override;
  std::string describe() const override;
  const std::vector<Box>& boxes() const { return boxes_; }

 private:
  grid::GridGeometry geometry_;
  std::vector<Box> boxes_;
  mutable int last_ = 0;  // the box of the previous query (queries come in spatial order); not thread-safe
};

/// max over ranks of `local_count`, divided by the mean (1 = perfectly balanced).
double imbalance(const class Communicator& comm, std::size_t local_count);

}  // namespace viscompm::parallel
