// The Newton matrix H = M + Δt² ∇²Φ as a Tpetra operator, in two forms built from the same
// per-particle pieces: assembled into a CrsMatrix, or applied matrix-free (the paper's §5.7
// solver). Both are owner computes: owned rows from own and ghost particles. Rows of nodes
// without mass (the partition's padding) are identity rows scaled by massless_row_scale.
// Private to src/linalg.
#pragma once

#include <memory>

#include "node_space_impl.hpp"
#include "viscompm/implicit/incremental_potential.hpp"

namespace viscompm::linalg {

class HessianOperator {
 public:
  virtual ~HessianOperator() = default;
  /// Builds the sparsity pattern (and whatever else depends only on the node space) for the
  /// NodeSpace's current partition (collective).
  virtual void build_pattern() = 0;
  /// Prepares H at grid velocities v on the current pattern (collective).
  virtual void update(const implicit::IncrementalPotential& potential, const NodeVectorField& v, bool project) = 0;
  virtual Teuchos::RCP<const operator_type> op() const = 0;
  /// The assembled matrix, or null when matrix-free.
  virtual Teuchos::RCP<crs_matrix_type> matrix() const = 0;
  /// diag(H) on the owned dofs (exact in both forms).
  virtual Teuchos::RCP<const vector_type> diagonal() const = 0;
  /// Global number of entries of H's sparsity pattern (the assembled one, also when matrix-free).
  virtual std::int64_t nonzeros() const = 0;
};

std::unique_ptr<HessianOperator> make_assembled_hessian(const NodeSpace& space);
std::unique_ptr<HessianOperator> make_matrix_free_hessian(const NodeSpace& space);

/// The diagonal of the rows of nodes without mass: the mean mass of the nodes with mass
/// (collective), so that those rows are scaled like the others.
double massless_row_scale(const implicit::IncrementalPotential& potential, const parallel::Communicator& comm);

}  // namespace viscompm::linalg
