// Block Jacobi on grid lines, built and applied by viscompm (solver files: Cycle = lean): the
// blocks are the runs of grid nodes along each axis (grid/node_lines), three dofs per node, each
// factored once per set-up (LAPACK's banded Cholesky, dpbtrf, of the block of H: at most
// 3 × Line length rows, nodes coupled to the next two along the line, so a band of 8 below the
// diagonal) and applied as one pass of banded solves (dpbtrs), summed over the overlapping lines:
//   y = ω Σ_ℓ R_ℓᵀ B_ℓ⁻¹ R_ℓ x,   ω = Line damping / λmax(Σ_ℓ R_ℓᵀ B_ℓ⁻¹ R_ℓ A).
// A line whose block is not positive definite (H assembled unprojected can be indefinite) uses
// B_ℓ = |diag| of its block, so that the smoother stays SPD.
// The same blocks as Ifpack2's BLOCK_RELAXATION with user parts, without its per-application
// copies into containers, weights and residual (measured: doc/performance.md). Private to src/linalg.
#pragma once

#include <functional>
#include <vector>

#include "linalg_types.hpp"

namespace viscompm::linalg {

/// λmax of S A by power iterations (S a smoother applied as `smooth(in, out)`): 12 from a fixed
/// start when `eigenvector` is null or of another length, 5 from the last estimate's vector after
/// that; `eigenvector` keeps the vector for the next estimate (collective).
double smoothed_largest_eigenvalue(const operator_type& A, const std::function<void(const vector_type&, vector_type&)>& smooth,
                                   Teuchos::RCP<vector_type>& eigenvector);

class LineSmoother {
 public:
  /// Lines of the matrix's owned nodes (node k: rows 3k, 3k+1, 3k+2).
  explicit LineSmoother(std::vector<std::vector<std::size_t>> lines) : lines_(std::move(lines)) {}
  /// Factors every line's block of A (its owned rows); then estimates the damping with power
  /// iterations of (blocks⁻¹ A) — 12 from a fixed start the first time, 5 from the last estimate
  /// after that (collective).
  void compute(const crs_matrix_type& A, const operator_type& apply_A, double line_damping);
  /// y = ω Σ_ℓ R_ℓᵀ B_ℓ⁻¹ R_ℓ x on the owned dofs.
  void apply(const multivector_type& x, multivector_type& y) const { apply_scaled(x, y, damping_); }
  /// y = Σ_ℓ R_ℓᵀ B_ℓ⁻¹ R_ℓ x: the blocks' inverse without the damping (a Chebyshev smoother's
  /// preconditioner).
  void apply_undamped(const multivector_type& x, multivector_type& y) const { apply_scaled(x, y, 1.0); }
  double damping() const { return damping_; }
  /// λmax(Σ_ℓ R_ℓᵀ B_ℓ⁻¹ R_ℓ A) as the last compute() estimated it.
  double largest_eigenvalue() const { return largest_eigenvalue_; }

 private:
  void apply_scaled(const multivector_type& x, multivector_type& y, double scale) const;
  /// y += Σ_ℓ R_ℓᵀ B_ℓ⁻¹ R_ℓ x for column j (no damping).
  template <class In, class Out>
  void solve_blocks(const In& x, Out& y, std::size_t j) const;
  /// A line's block factored by dpbtrf, lower band storage: (bandwidth + 1) × rows, column-major.
  struct BandFactor {
    int rows = 0, bandwidth = 0;
    int graph_bandwidth = 0;  // of the line's block in A's graph (a line smoothed by |diag| has 0)
    std::vector<double> band;
  };
  /// Where each row and column of A lies on the lines, and each line's band, from A's graph
  /// (once per graph: the values change, the graph does not).
  void index_lines(const crs_matrix_type& A);
  /// visit(line's factor, i, j, value) for every entry of A in a line's block on or below its
  /// diagonal (i ≥ j, positions in the block).
  template <class Visit>
  void for_each_line_entry(const crs_matrix_type& A, Visit&& visit);
  std::vector<std::vector<std::size_t>> lines_;
  std::vector<BandFactor> factors_;
  const crs_graph_type* indexed_graph_ = nullptr;  // the graph the indices below are for
  std::vector<int> column_row_;                     // local column → local row (−1: ghost)
  std::vector<int> line_of_, position_of_;          // per node and axis: its line, its place on it
  double damping_ = 1.0;
  double largest_eigenvalue_ = 1.0;
  Teuchos::RCP<vector_type> eigenvector_;  // of the last estimate
};

}  // namespace viscompm::linalg
