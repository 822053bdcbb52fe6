// The RCB boxes of rebalancing (Zoltan2): migrating to them conserves every particle and puts it
// on its owner, and they even out a skewed distribution. Registered on 2 and 4 ranks (one rank
// has nothing to balance).
#include <gtest/gtest.h>

#include <numeric>
#include <random>
#include <set>

#include "gather.hpp"
#include "particle_checks.hpp"
#include "viscompm/parallel/migration.hpp"
#include "viscompm/linalg/rcb_partition.hpp"

using namespace viscompm;

using testkit::Totals;
using testkit::totals;
using testkit::expect_conserved;
using testkit::expect_on_owners;
using testkit::random_particles;

TEST(RcbPartition, MigrationToItsBoxesConservesEveryParticle) {
  const parallel::Communicator comm(MPI_COMM_WORLD);
  grid::GridGeometry g;
  g.dx = 0.1;
  g.cells = Int3(24, 18, 12);
  particles::ParticleSet ps = random_particles(comm, g, 5000, Vec3(2, 2, 2), Vec3(22, 16, 10));
  const Totals start = totals(ps, comm);
  const auto ids_before = testkit::gather_particles(ps, comm.comm());

  const parallel::BlockDecomposition blocks(g, comm.size());
  parallel::migrate_particles(comm, blocks, g, grid::KernelOrder::quadratic, ps);
  expect_conserved(start, totals(ps, comm));
  expect_on_owners(ps, blocks, g, comm);

  const auto rcb = linalg::make_rcb_decomposition(comm, g, ps);
  parallel::migrate_particles(comm, *rcb, g, grid::KernelOrder::quadratic, ps);
  expect_conserved(start, totals(ps, comm));
  expect_on_owners(ps, *rcb, g, comm);

  // The same ids, each once (gather_particles throws on a duplicate).
  const auto ids_after = testkit::gather_particles(ps, comm.comm());
  ASSERT_EQ(ids_after.size(), ids_before.size());
  for (const auto& [id, state] : ids_before) EXPECT_EQ(ids_after.count(id), 1u) << id;
}

TEST(RcbPartition, BoxesBalanceASkewedDistribution) {
  const parallel::Communicator comm(MPI_COMM_WORLD);
  grid::GridGeometry g;
  g.dx = 0.05;
  g.cells = Int3(40, 40, 40);
  // Everything in one corner: the block decomposition gives it to one rank.
  particles::ParticleSet ps = random_particles(comm, g, 20000, Vec3(2, 2, 2), Vec3(14, 18, 16));
  const parallel::BlockDecomposition blocks(g, comm.size());
  parallel::migrate_particles(comm, blocks, g, grid::KernelOrder::quadratic, ps);
  const double skewed = parallel::imbalance(comm, ps.size());
  const auto rcb = linalg::make_rcb_decomposition(comm, g, ps);
  parallel::migrate_particles(comm, *rcb, g, grid::KernelOrder::quadratic, ps);
  const double balanced = parallel::imbalance(comm, ps.size());
  EXPECT_GT(skewed, 1.5);
  EXPECT_LT(balanced, 1.15) << "from " << skewed;
}
