// The preconditioners of a SolverConfiguration on the Newton matrix: none, Jacobi (also
// matrix-free), Ifpack2 and MueLu (algebraic or on the grid's own hierarchy), and what they need
// to know besides the matrix (node coordinates, rigid-body modes, the grid). Private to src/linalg.
#pragma once

#include <functional>
#include <memory>
#include <vector>

#include "hessian_operator.hpp"
#include "solver_configuration_impl.hpp"
#include "linalg_types.hpp"

namespace viscompm::linalg {

/// The grid behind a system, for geometric multigrid: the grid's nodes per axis, the owned nodes'
/// grid indices in the row order of the matrix (3 rows per node), and the rank owning a grid node.
struct SystemGrid {
  Int3 dimensions = Int3::Zero();
  std::vector<Int3> owned_nodes;
  std::function<int(const Int3&)> owner;
};

/// Node data a multigrid preconditioner needs besides the matrix: coordinates of the owned
/// nodes (one row per node), the 6 rigid-body modes on the owned dofs, and the grid.
struct NearNullspace {
  Teuchos::RCP<multivector_type> coordinates;
  Teuchos::RCP<multivector_type> rigid_body_modes;
  std::shared_ptr<const SystemGrid> grid;
};

/// The 6 rigid-body modes (translations, rotations e_a × x about the axes) on `dof_map`, 3 dofs
/// per node in node order, from the owned nodes' coordinates (one row of x, y, z per node).
Teuchos::RCP<multivector_type> rigid_body_modes(const multivector_type& coordinates,
                                                const Teuchos::RCP<const map_type>& dof_map);

class Preconditioner {
 public:
  virtual ~Preconditioner() = default;
  /// Builds (pattern_changed) or refreshes the preconditioner for the current values of H.
  virtual void setup(const HessianOperator& H, bool pattern_changed, const NearNullspace& modes) = 0;
  /// The operator to apply, null for no preconditioning.
  virtual Teuchos::RCP<operator_type> op() const = 0;
  /// Global rows of every level of a multigrid hierarchy, finest first (empty otherwise).
  virtual std::vector<std::int64_t> level_rows() const { return {}; }
  /// The matrix of a multigrid level (null if there is none).
  virtual Teuchos::RCP<const crs_matrix_type> level_matrix(int) const { return Teuchos::null; }
};

std::unique_ptr<Preconditioner> make_preconditioner(const SolverConfiguration& config);

}  // namespace viscompm::linalg
