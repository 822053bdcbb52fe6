// Shared helpers of the tests: random states, finite differences, one-rank grid layouts.
#pragma once

#include <random>

#include "viscompm/grid/grid_layout.hpp"
#include "viscompm/parallel/node_partition.hpp"
#include "viscompm/particles/binning.hpp"
#include "viscompm/particles/particle_set.hpp"

namespace viscompm::testkit {

inline std::mt19937& rng() {
  static std::mt19937 generator(20151127);
  return generator;
}

inline double uniform(double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(rng()); }

inline Mat3 random_matrix(double scale) {
  Mat3 m;
  for (int i = 0; i < 9; ++i) m.data()[i] = uniform(-scale, scale);
  return m;
}

/// A random symmetric positive definite matrix near the identity.
inline Mat3 random_spd(double spread) {
  const Mat3 r = Mat3::Identity() + random_matrix(spread);
  return r * r.transpose();
}

/// Central difference of a scalar function of a 3x3 matrix, entry by entry (column-major vec).
template <class F>
Vec9 finite_difference_gradient(F&& f, const Mat3& x, double h) {
  Vec9 g;
  for (int k = 0; k < 9; ++k) {
    Mat3 plus = x, minus = x;
    plus.data()[k] += h;
    minus.data()[k] -= h;
    g[k] = (f(plus) - f(minus)) / (2.0 * h);
  }
  return g;
}

/// A layout for one rank without padding: the nodes are those the particles touch, all owned.
inline grid::GridLayout serial_layout(particles::ParticleSet& particles, const grid::GridGeometry& geometry,
                                      grid::KernelOrder order) {
  grid::GridLayout layout;
  layout.geometry = geometry;
  layout.order = order;
  particles::bin_particles(particles, 0, layout);
  layout.own_cell_count = layout.cells.size();
  std::vector<parallel::PaddedCell> cells;
  for (const NodeId c : layout.cells) cells.push_back({c, Int3::Zero(), Int3::Zero()});
  const parallel::Communicator self(MPI_COMM_SELF);
  const parallel::BlockDecomposition one_block(geometry, 1);
  const parallel::NodePartition partition(self, geometry, order, one_block, cells);
  layout.nodes = partition.nodes();
  layout.owned_count = partition.owned_count();
  partition.index_cells(layout.cells, 0, layout.cell_count(), layout.cell_nodes);
  return layout;
}

}  // namespace viscompm::testkit
