// The MPM grid as a geometric multigrid hierarchy: grids of spacing 2Δx, 4Δx, ... whose node
// (I, J, K) at level ℓ sits on grid node origin_ℓ + 2^ℓ (I, J, K) of level 0 (origin_ℓ = 0 for
// trilinear prolongation; one coarse spacing lower per level for the B-spline, whose support
// reaches a coarse node beyond the grid), and the prolongations between them, per axis:
//   trilinear:            a fine node at an even index copies its coarse node, one at an odd
//                         index averages its two neighbours (weights 1 | ½ ½);
//   quadratic B-spline:   the coarse quadratic B-spline N(d/2) evaluated at the fine nodes
//                         (weights ⅛ ¾ ⅛ at even indices | ½ ½ at odd ones);
//   piecewise constant:   fine nodes 2k and 2k + 1 copy coarse node k (aggregates of 2×2×2
//                         nodes with unsmoothed prolongation: brick aggregation, made geometric).
// The first two reproduce linear fields, the third constants only; a 3D weight is the product of the axes'. A coarse level holds the
// coarse nodes some finer node interpolates from; each is owned by the rank that owns its level-0
// position (clamped to the grid: its fine twin), so levels follow the fine ownership. Built from local arrays with
// a few personalised exchanges (collective); rank-independent. Trilinos-free: linalg turns the
// levels into Tpetra prolongators for MueLu.
#pragma once

#include <cstdint>
#include <functional>
#include <vector>

#include "viscompm/core/types.hpp"
#include "viscompm/parallel/communicator.hpp"

namespace viscompm::parallel {

enum class Prolongation { trilinear, quadratic_bspline, piecewise_constant };

/// One coarse level and the prolongation from the level below it.
struct CoarseLevel {
  Int3 dimensions = Int3::Zero();      ///< nodes per axis of this level's index space
  int spacing = 2;                     ///< 2^ℓ: level-0 grid cells between neighbouring nodes
  int origin = 0;                      ///< level-0 index (every axis) of this level's node 0
  /// Local nodes (ids I + nx (J + ny K) of this level): [0, owned_count) owned (ascending), then
  /// ghosts (by owner, then id): the columns of the prolongation rows of this rank.
  std::vector<NodeId> nodes;
  std::size_t owned_count = 0;
  std::vector<std::int64_t> system_ids;  ///< contiguous by rank, for every local node
  std::vector<int> ghost_owners;         ///< owner of each ghost (local index − owned_count)
  std::int64_t global_count = 0;
  /// Prolongation rows, one per owned node of the finer level (in its local order): columns
  /// (local nodes of this level, ascending) and weights in [row_begin[r], row_begin[r + 1]).
  std::vector<std::size_t> row_begin;
  std::vector<int> columns;
  std::vector<double> weights;
};

struct HierarchySettings {
  Prolongation prolongation = Prolongation::trilinear;
  int max_levels = 10;                  ///< levels including the finest
  std::int64_t coarsest_nodes = 2000;   ///< stop once a level has at most this many nodes
  std::int64_t always_coarsen_above = 64;  ///< but coarsen once at least when the fine level has more
};

/// The coarse levels below a fine level whose owned nodes are `owned_fine` (grid indices of
/// level 0, in the fine level's local order) on a grid of `fine_dimensions` nodes per axis;
/// `owner` gives the rank owning a level-0 grid node. Collective.
std::vector<CoarseLevel> build_grid_hierarchy(const Communicator& comm, const Int3& fine_dimensions,
                                              const std::vector<Int3>& owned_fine,
                                              const std::function<int(const Int3&)>& owner,
                                              const HierarchySettings& settings);

}  // namespace viscompm::parallel
