// The geometric hierarchy of the MPM grid (parallel/grid_hierarchy): the trilinear and B-spline
// prolongations reproduce linear fields exactly, all three are partitions of unity, every coarse
// node is a parent of some finer node, and the levels (node sets and counts) do not depend on the
// rank count.
#include <gtest/gtest.h>

#include <algorithm>
#include <set>

#include "gather.hpp"
#include "test_helpers.hpp"
#include "viscompm/grid/grid_geometry.hpp"
#include "viscompm/parallel/decomposition.hpp"
#include "viscompm/parallel/grid_hierarchy.hpp"

using namespace viscompm;

namespace {
// An irregular blob of grid nodes (a ball with a bite out of it), the part owned by this rank's block.
std::vector<Int3> blob_nodes(const grid::GridGeometry& g, const parallel::Decomposition& d, int rank) {
  std::vector<Int3> nodes;
  for (int z = 0; z <= g.cells.z(); ++z)
    for (int y = 0; y <= g.cells.y(); ++y)
      for (int x = 0; x <= g.cells.x(); ++x) {
        const Vec3 p(x, y, z);
        const bool ball = (p - Vec3(14, 12, 11)).norm() < 9.5;
        const bool bite = (p - Vec3(20, 12, 11)).norm() < 4.0;
        if (ball && !bite && d.owner_of_node(Int3(x, y, z)) == rank) nodes.emplace_back(x, y, z);
      }
  return nodes;
}

std::vector<parallel::CoarseLevel> hierarchy(const parallel::Communicator& comm, parallel::Prolongation kind,
                                             std::int64_t coarsest_nodes = 20) {
  grid::GridGeometry g;
  g.cells = Int3(28, 25, 23);
  const parallel::BlockDecomposition d(g, comm.size());
  parallel::HierarchySettings settings;
  settings.prolongation = kind;
  settings.coarsest_nodes = coarsest_nodes;
  return parallel::build_grid_hierarchy(comm, g.nodes(), blob_nodes(g, d, comm.rank()),
                                        [&d](const Int3& ijk) { return d.owner_of_node(ijk); }, settings);
}

Int3 index_of(NodeId id, const Int3& dims) {
  return Int3(static_cast<int>(id % dims.x()), static_cast<int>((id / dims.x()) % dims.y()),
              static_cast<int>(id / (static_cast<NodeId>(dims.x()) * dims.y())));
}
}  // namespace

class GridHierarchyTest : public ::testing::TestWithParam<parallel::Prolongation> {};

TEST_P(GridHierarchyTest, ASystemSmallerThanTheCoarsestLevelStillGetsOneCoarseLevel) {
  // ~3 400 nodes under a Coarsest nodes of 10⁶: one coarse level, at least halving the nodes (the
  // B-spline level keeps a ring of parents around the blob), and no more.
  const parallel::Communicator comm(MPI_COMM_WORLD);
  grid::GridGeometry g;
  g.cells = Int3(28, 25, 23);
  const parallel::BlockDecomposition d(g, comm.size());
  const auto fine = comm.sum(static_cast<std::int64_t>(blob_nodes(g, d, comm.rank()).size()));
  const auto levels = hierarchy(comm, GetParam(), 1000000);
  ASSERT_EQ(levels.size(), 1u);
  EXPECT_LT(2 * levels[0].global_count, fine);
  EXPECT_GT(levels[0].global_count, 1);
}

TEST_P(GridHierarchyTest, ProlongationReproducesLinearFieldsAndConstants) {
  const parallel::Communicator comm(MPI_COMM_WORLD);
  const auto levels = hierarchy(comm, GetParam());
  ASSERT_GE(levels.size(), 2u) << "the blob coarsens at least twice";
  grid::GridGeometry g;
  g.cells = Int3(28, 25, 23);
  const parallel::BlockDecomposition d(g, comm.size());
  std::vector<Int3> fine = blob_nodes(g, d, comm.rank());  // level-0 indices of the finer level's owned nodes
  const Vec3 a(0.3, -1.7, 2.9);
  const double b = 4.2;
  double worst_linear = 0.0, worst_sum = 0.0;
  for (std::size_t l = 0; l < levels.size(); ++l) {
    const auto& c = levels[l];
    auto position = [&](NodeId id) -> Int3 { return Int3::Constant(c.origin) + c.spacing * index_of(id, c.dimensions); };
    ASSERT_EQ(c.row_begin.size(), fine.size() + 1);
    for (std::size_t r = 0; r < fine.size(); ++r) {
      double value = 0.0, sum = 0.0;
      for (std::size_t k = c.row_begin[r]; k < c.row_begin[r + 1]; ++k) {
        const Vec3 X = position(c.nodes[c.columns[k]]).cast<double>();
        value += c.weights[k] * (a.dot(X) + b);
        sum += c.weights[k];
      }
      worst_linear = std::max(worst_linear, std::abs(value - (a.dot(fine[r].cast<double>()) + b)));
      worst_sum = std::max(worst_sum, std::abs(sum - 1.0));
    }
    fine.clear();
    for (std::size_t k = 0; k < c.owned_count; ++k) fine.push_back(position(c.nodes[k]));
  }
  if (GetParam() != parallel::Prolongation::piecewise_constant) EXPECT_LT(comm.max(worst_linear), 1e-12);
  else EXPECT_GT(comm.max(worst_linear), 0.1) << "aggregates reproduce constants, not linear fields";
  EXPECT_LT(comm.max(worst_sum), 1e-14);
}

TEST_P(GridHierarchyTest, LevelsAreTheParentsOfTheFinerNodesWhateverTheRankCount) {
  const parallel::Communicator world(MPI_COMM_WORLD);
  const auto levels = hierarchy(world, GetParam());
  // Every owned coarse node is referenced by some row of some rank (a parent), and each node is
  // owned once: the counts add up and the gathered ids are unique.
  for (const auto& c : levels) {
    std::vector<std::int64_t> referenced(c.columns.begin(), c.columns.end()), owned;
    std::set<NodeId> local_referenced;
    for (int column : c.columns) local_referenced.insert(c.nodes[column]);
    std::vector<std::int64_t> ids(local_referenced.begin(), local_referenced.end());
    for (std::size_t k = 0; k < c.owned_count; ++k) owned.push_back(c.nodes[k]);
    auto all_referenced = world.all_gather(ids), all_owned = world.all_gather(owned);
    std::sort(all_referenced.begin(), all_referenced.end());
    all_referenced.erase(std::unique(all_referenced.begin(), all_referenced.end()), all_referenced.end());
    std::sort(all_owned.begin(), all_owned.end());
    EXPECT_EQ(all_owned, all_referenced);
    EXPECT_EQ(static_cast<std::int64_t>(all_owned.size()), c.global_count);
  }
  // The same levels on one rank.
  std::vector<std::int64_t> counts;
  for (const auto& c : levels) counts.push_back(c.global_count);
  if (MPI_Comm solo = testkit::solo_communicator(); solo != MPI_COMM_NULL) {
    const auto alone = hierarchy(parallel::Communicator(solo), GetParam());
    ASSERT_EQ(alone.size(), levels.size());
    for (std::size_t l = 0; l < levels.size(); ++l) EXPECT_EQ(alone[l].global_count, counts[l]) << "level " << l + 1;
    MPI_Comm_free(&solo);
  }
}

INSTANTIATE_TEST_SUITE_P(Prolongations, GridHierarchyTest,
                         ::testing::Values(parallel::Prolongation::trilinear, parallel::Prolongation::quadratic_bspline,
                                           parallel::Prolongation::piecewise_constant),
                         [](const auto& info) {
                           switch (info.param) {
                             case parallel::Prolongation::trilinear: return "trilinear";
                             case parallel::Prolongation::quadratic_bspline: return "quadratic_bspline";
                             default: return "piecewise_constant";
                           }
                         });
