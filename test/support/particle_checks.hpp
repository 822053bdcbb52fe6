// Checks shared by the migration and rebalancing tests: particles conserved (count, mass,
// momentum) and each on its owner, and random particles created on rank 0.
#pragma once

#include <gtest/gtest.h>

#include <random>

#include "viscompm/parallel/migration.hpp"

namespace viscompm::testkit {
struct Totals {
  std::int64_t count;
  double mass;
  Vec3 momentum;
};

inline Totals totals(const particles::ParticleSet& ps, const parallel::Communicator& comm) {
  double mass = 0.0;
  Vec3 momentum = Vec3::Zero();
  for (std::size_t p = 0; p < ps.size(); ++p) {
    mass += ps.mass[p];
    momentum += ps.mass[p] * ps.velocity[p];
  }
  return {comm.sum(static_cast<std::int64_t>(ps.size())), comm.sum(mass),
          Vec3(comm.sum(momentum.x()), comm.sum(momentum.y()), comm.sum(momentum.z()))};
}

inline void expect_conserved(const Totals& before, const Totals& after) {
  EXPECT_EQ(after.count, before.count);
  EXPECT_NEAR(after.mass, before.mass, 1e-12 * before.mass);
  EXPECT_LT((after.momentum - before.momentum).norm(), 1e-12 * before.mass);
}

inline void expect_on_owners(const particles::ParticleSet& ps, const parallel::Decomposition& d, const grid::GridGeometry& g,
                      const parallel::Communicator& comm) {
  int misplaced = 0;
  for (const Vec3& x : ps.position) misplaced += parallel::particle_owner(d, g, grid::KernelOrder::quadratic, x) != comm.rank();
  EXPECT_EQ(comm.sum(static_cast<std::int64_t>(misplaced)), 0);
}

// `n` particles with random positions in [lo, hi] (cells), created on rank 0 only.
inline particles::ParticleSet random_particles(const parallel::Communicator& comm, const grid::GridGeometry& g, int n,
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
}  // namespace viscompm::testkit
