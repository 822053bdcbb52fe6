// The Newton matrix H = M + Δt² ∇²Φ and its solve with Belos CG and the configured
// preconditioner. H is either assembled (owner computes: owned rows from own and ghost
// particles) into a Tpetra CrsMatrix whose graph is the node partition's windows, built once per
// partition, or applied matrix-free from the same per-particle pieces (the paper's §5.7). The
// three phases are separate calls, so that a Newton strategy can reuse H or its preconditioner:
// assemble, precondition, solve.
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
  /// A system on `space` (its pattern is built at once if the space has a partition).
  NewtonSystem(const NodeSpace& space, const SolverConfiguration& config);
  ~NewtonSystem();
  NewtonSystem(const NewtonSystem&) = delete;
  NewtonSystem& operator=(const NewtonSystem&) = delete;

  /// Builds H's sparsity pattern for the NodeSpace's current partition (collective): call after
  /// every NodeSpace::update.
  void build_pattern();
  /// Assembles H at grid velocities v (collective); particle Hessians projected to PSD if
  /// `project`. Returns the seconds it took.
  double assemble(const implicit::IncrementalPotential& potential, const NodeVectorField& v, bool project);
  /// Sets up the preconditioner for the current H (or refreshes it, reusing what the solver file's
  /// reuse options allow). Returns the seconds it took. The caller decides when (newton::ReuseRules
  /// in a run): solve and apply_preconditioner never set it up themselves.
  double precondition();
  /// Builds the pattern if the node space changed since it was built (collective); seconds.
  double prepare();
  /// The NodeSpace version the pattern was built for.
  std::uint64_t pattern_version() const;
  /// True once precondition() has run for the current sparsity pattern.
  bool preconditioned() const;
  /// Solves H dv = rhs from dv = 0 to the relative residual `tolerance` (≤ 0: the solver file's)
  /// with the last preconditioner, which must have been set up for the current pattern
  /// (std::logic_error otherwise); rhs on the owned nodes, dv returned on all local nodes.
  LinearSolveReport solve(const NodeVectorField& rhs, NodeVectorField& dv, double tolerance = 0.0, int max_iterations = 0);
  /// z = P⁻¹ r, one application of the current preconditioner (set up as for solve; z = r
  /// without one); r on the owned nodes, z returned on all local nodes. Collective.
  void apply_preconditioner(const NodeVectorField& r, NodeVectorField& z);
  /// False for a configuration without a preconditioner.
  bool has_preconditioner() const;
  /// Global rows of each level of a multigrid preconditioner, finest first (empty otherwise).
  std::vector<std::int64_t> preconditioner_levels() const;
  /// Every entry of level `level` of a multigrid preconditioner as (row, column, value) in that
  /// level's system dof ids (3 · node system id + d), on every rank, sorted (collective).
  std::vector<std::tuple<long long, long long, double>> preconditioner_level_entries(int level) const;
  /// The solver file's relative CG tolerance.
  double default_tolerance() const;

  /// y = H x (x and y on all local nodes; owned entries of x are used). Collective.
  void apply(const NodeVectorField& x, NodeVectorField& y) const;

  std::int64_t global_rows() const;
  /// Entries of the assembled matrix; -1 when matrix-free.
  std::int64_t global_nonzeros() const;
  bool matrix_free() const;
  /// Every entry of H as (row, column, value) with grid dof ids 3·(grid node id) + d, which do not
  /// depend on the rank count; on every rank, sorted (collective; assembled operators only).
  std::vector<std::tuple<long long, long long, double>> gather_entries() const;
  /// Writes H of the last assembly at grid velocities v and a right-hand side (owned entries of
  /// `rhs`) to PREFIX.mtx and PREFIX_rhs.mtx, renumbered to contiguous indices 1..n. A
  /// matrix-free operator's H is assembled for the file from the same per-particle pieces
  /// (collective).
  void write_matrix_market(const std::string& prefix, const implicit::IncrementalPotential& potential,
                           const NodeVectorField& v, const NodeVectorField& rhs) const;
  /// Seconds per application of H (mean of `repetitions`), for benchmarks (collective).
  double time_apply(int repetitions) const;
  /// The same product with H stored as 3×3 blocks (Tpetra::BlockCrsMatrix converted from the
  /// assembled matrix): seconds per application, and the conversion's seconds in
  /// `convert_seconds`; for benchmarks (collective; assembled operators only).
  double time_block_apply(int repetitions, double& convert_seconds) const;
  /// Seconds per application of the preconditioner (mean of `repetitions`; 0 without one): one
  /// V-cycle of a multigrid (collective; after precondition()).
  double time_preconditioner(int repetitions) const;
  const SolverConfiguration& configuration() const;

  struct Impl;

 private:
  void require_preconditioner(const char* caller) const;
  std::unique_ptr<Impl> impl_;
};

}  // namespace viscompm::linalg
