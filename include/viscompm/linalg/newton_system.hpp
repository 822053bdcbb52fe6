// The Newton matrix H = M + Δt² ∇²Φ and its solve with Belos CG and the configured
// preconditioner. H is either assembled from per-cell element matrices into a Tpetra
// FECrsMatrix (owned and shared rows, zeroed each assembly, shared rows summed into their
// owners; the graph is built once per set of occupied cells and reused while the particles keep
// the same cells), or applied matrix-free from the same per-particle pieces (the paper's §5.7).
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <tuple>
#include <vector>

#include "viscompm/implicit/incremental_potential.hpp"
#include "viscompm/linalg/linear_solver.hpp"
#include "viscompm/linalg/node_space.hpp"

namespace viscompm::linalg {

class NewtonSystem {
 public:
  NewtonSystem(const NodeSpace& space, const SolverConfiguration& config);
  ~NewtonSystem();
  NewtonSystem(const NewtonSystem&) = delete;
  NewtonSystem& operator=(const NewtonSystem&) = delete;

  /// Assembles H at grid velocities v (collective); particle Hessians projected to PSD if
  /// `project`.
  void assemble(const implicit::IncrementalPotential& potential, const NodeVectorField& v, bool project);
  /// Solves H dv = rhs from dv = 0 (rhs: totals on the local nodes, owned entries used); dv is
  /// returned on all local nodes. Sets up the preconditioner first if H changed.
  LinearSolveReport solve(const NodeVectorField& rhs, NodeVectorField& dv);

  /// y = H x (x and y on all local nodes; owned entries of x are used). Collective.
  void apply(const NodeVectorField& x, NodeVectorField& y) const;

  std::int64_t global_rows() const;
  /// Entries of the assembled matrix; -1 when matrix-free.
  std::int64_t global_nonzeros() const;
  bool matrix_free() const;
  /// Seconds spent in the last assemble().
  double assembly_seconds() const;
  /// How many times the graph has been built.
  int graph_builds() const;
  /// Every entry of H as (row, column, value) with grid dof ids 3·(grid node id) + d, which do not
  /// depend on the rank count; on every rank, sorted (collective; assembled operators only).
  std::vector<std::tuple<long long, long long, double>> gather_entries() const;
  /// Writes H and a right-hand side (owned entries of `rhs`) to PREFIX.mtx and PREFIX_rhs.mtx,
  /// renumbered to contiguous indices 1..n (collective; assembled operators only).
  void write_matrix_market(const std::string& prefix, const NodeVectorField& rhs) const;
  /// Seconds per application of H (mean of `repetitions`), for benchmarks (collective).
  double time_apply(int repetitions) const;
  const SolverConfiguration& configuration() const;

  struct Impl;

 private:
  std::unique_ptr<Impl> impl_;
};

}  // namespace viscompm::linalg
