// The Hessian of one cell's particles over the cell's stencil (the element of the assembly):
//   E(i σ, j τ) = Σ_p Σ_{β,κ} ∇w_ip[β] H_p(σ+3β, τ+3κ) ∇w_jp[κ],
// with H_p = Δt² ∂²Φ_p/∂vec(A)² (Appendix A: Φ_p depends on the grid velocities only through
// A_p = Δt Σ_i v_i ∇w_ipᵀ). Contracted in two stages, per node then per node pair, upper block
// triangle only (i ≤ j), with the particles of the cell summed before anything is scattered.
// Storage is node-pair lanes (j fastest, padded to a multiple of 4) so both stages vectorise.
#pragma once

#include <vector>

#include "viscompm/core/types.hpp"

namespace viscompm::implicit {

class ElementHessian {
 public:
  explicit ElementHessian(int nodes_per_cell);

  int nodes() const { return nodes_; }
  /// Zeroes the element.
  void clear();
  /// Adds the block of one particle: `h` its (already Δt²-scaled) 9×9 Hessian in vec(A), `dw`
  /// the weight gradients of its stencil nodes (nodes() of them).
  void add_particle(const Mat9& h, const Vec3* dw);
  /// Entry (σ, τ) of block (i, j), i ≤ j.
  double entry(int i, int j, int sigma, int tau) const {
    return element_[(static_cast<std::size_t>(i) * 9 + 3 * sigma + tau) * lanes_ + j];
  }
  /// Block (i, j) as a 3×3 matrix, i ≤ j.
  Mat3 block(int i, int j) const;
  /// The entries (i, σ, τ) for every j ≥ i: row 3σ + τ of node i's lanes (entry j at index j).
  const double* lanes(int i, int sigma, int tau) const {
    return element_.data() + (static_cast<std::size_t>(i) * 9 + 3 * sigma + tau) * lanes_;
  }

 private:
  int nodes_;
  int lanes_;                     // nodes_ rounded up to a multiple of 4
  std::vector<double> element_;   // (i, σ, τ) rows of `lanes_` entries j
  std::vector<double> stage_;     // G_j[β](σ, τ) = Σ_κ H(σ+3β, τ+3κ) ∇w_j[κ]: (β, σ, τ) rows of lanes
  std::vector<double> gradients_; // ∇w_j[β]: 3 rows of lanes
};

}  // namespace viscompm::implicit
