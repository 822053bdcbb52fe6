// The RCB boxes of rebalancing (Zoltan2): migrating to them conserves every particle and puts it
// on its owner, and they even out a skewed distribution. Registered on 2 and 4 ranks (one rank
// has nothing to balance).
#include <gtest/gtest.h>

#include <numeric>
#include <random>
#include <set>

#include "gather.hpp"
#include "viscompm/parallel/migration.hpp"
#include "viscompm/linalg/rcb_partition.hpp"

using namespace viscompm;

namespace {
struct Totals {
  std::int64_t count;
  double mass;
  Vec3 momentum;
};

Totals totals(const particles::ParticleSet& ps, const parallel::Communicator& comm) {
  double mass = 0.0;
  Vec3 momentum = Vec3::Zero();
  for (std::size_t p = 0; p < ps.size(); ++p) {
    mass += ps.mass[p];
    momentum += ps.mass[p] * ps.velocity[p];
  }
  return {comm.sum(static_cast<std::int64_t>(ps.size())), comm.sum(mass),
          Vec3(comm.sum(momentum.x()), comm.sum(momentum.y()), comm.sum(momentum.z()))};
}

void expect_conserved(const Totals& before, const Totals& after) {
  EXPECT_EQ(after.count, before.count);
  EXPECT_NEAR(after.mass, before.mass, 1e-12 * before.mass);
  EXPECT_LT((after.momentum - before.momentum).norm(), 1e-12 * before.mass);
}

void expect_on_owners(const particles::ParticleSet& ps, const parallel::Decomposition& d, const grid::GridGeometry& g,
                      const parallel::Communicator& comm) {
  int misplaced = 0;
  for (const Vec3& x : ps.position) misplaced += parallel::particle_owner(d, g, grid::KernelOrder::quadratic, x) != comm.rank();
  EXPECT_EQ(comm.sum(static_cast<std::int64_t>(misplaced)), 0);
}

// `n` particles with random positions in [lo, hi] (cells), created on rank 0 only.
particles::ParticleSet random_particles(const parallel::Communicator& comm, const grid::GridGeometry& g, int n,
                                        const Vec3& lo, const Vec3& hi) {
  particles::ParticleSet ps;
  if (!comm.is_root()) return ps;
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int p = 0; p < n; ++p) {
    const Vec3 cell(lo.x() + u(rng) * (hi.x() - lo.x()), lo.y() + u(rng) * (hi.y() - lo.y()), lo.z() + u(rng) * (hi.z() - lo.z()));
    ps.add(1000 + 7 * p, g.origin + g.dx * cell, Vec3(u(rng), u(rng), u(rng)) - Vec3::Constant(0.5), 0.5 + u(rng), 1.0, 0);
  }
  return ps;
}
}  // namespace

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
