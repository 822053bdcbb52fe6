// Particle migration moves every particle to its owner with nothing lost or duplicated (ids,
// count, mass and momentum conserved) under block decompositions. Registered on 2 and 4 ranks
// (on one rank nothing moves); the RCB boxes of rebalancing are tested in test_rcb_partition.
#include <gtest/gtest.h>

#include <numeric>
#include <random>
#include <set>

#include "gather.hpp"
#include "particle_checks.hpp"
#include "viscompm/parallel/migration.hpp"

using namespace viscompm;

using testkit::Totals;
using testkit::totals;
using testkit::expect_conserved;
using testkit::expect_on_owners;
using testkit::random_particles;

TEST(Migration, ConservesEveryParticleUnderBlockDecompositions) {
  const parallel::Communicator comm(MPI_COMM_WORLD);
  grid::GridGeometry g;
  g.dx = 0.1;
  g.cells = Int3(24, 18, 12);
  particles::ParticleSet ps = random_particles(comm, g, 5000, Vec3(2, 2, 2), Vec3(22, 16, 10));
  const Totals start = totals(ps, comm);
  const auto ids_before = testkit::gather_particles(ps, comm.comm());
  // Particles sent between ranks, all ranks: the test sees a loss only if something moves.
  auto migrate = [&](const parallel::Decomposition& d) {
    return comm.sum(static_cast<std::int64_t>(parallel::migrate_particles(comm, d, g, grid::KernelOrder::quadratic, ps)));
  };

  const parallel::BlockDecomposition blocks(g, comm.size());
  EXPECT_GT(migrate(blocks), 0);
  expect_conserved(start, totals(ps, comm));
  expect_on_owners(ps, blocks, g, comm);

  // Move everything by up to two cells, migrate again.
  std::mt19937 rng(11 + comm.rank());
  std::uniform_real_distribution<double> u(-2.0, 2.0);
  for (Vec3& x : ps.position) x += g.dx * Vec3(u(rng), u(rng), u(rng));
  EXPECT_GT(migrate(blocks), 0);
  expect_conserved(start, totals(ps, comm));
  expect_on_owners(ps, blocks, g, comm);

  // The same ids, each once (gather_particles throws on a duplicate).
  const auto ids_after = testkit::gather_particles(ps, comm.comm());
  ASSERT_EQ(ids_after.size(), ids_before.size());
  for (const auto& [id, state] : ids_before) EXPECT_EQ(ids_after.count(id), 1u) << id;
}

