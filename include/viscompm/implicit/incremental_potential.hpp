// The objective of the implicit step (DESIGN.md §3, §5.5 with Gast et al. 2015):
//   E(v) = Σ_i ½ m_i |v_i − v_i^*|² + Σ_p Φ_p(A_p(v)),  A_p = Δt Σ_i v_i (∇w_ip)^T,
// with v^* = v^n + Δt g. This rank evaluates the pieces of its own particles and the inertia of
// the nodes it owns; sums across ranks are the caller's. Constrained components (colliders) are
// fixed: gradients and Hessian blocks are projected with P_i.
#pragma once

#include <Eigen/Core>
#include <functional>
#include <limits>

#include "viscompm/boundary/colliders.hpp"
#include "viscompm/grid/grid_layout.hpp"
#include "viscompm/materials/material.hpp"

namespace viscompm::implicit {

/// A dense element matrix over the 3K unknowns of one cell's stencil, row 3k + σ for stencil
/// node k and component σ.
using ElementMatrix = Eigen::MatrixXd;

struct EnergyValue {
  double value = 0.0;      ///< E on this rank (+∞ if a particle's state is infeasible)
  double magnitude = 0.0;  ///< Σ |terms|: the scale of rounding errors in `value`
  bool feasible() const { return value < std::numeric_limits<double>::infinity(); }
};

class IncrementalPotential {
 public:
  /// `mass` and `v_inertial` are the summed grid mass and v^n + Δt g on all local nodes.
  IncrementalPotential(const particles::ParticleSet& particles, const grid::GridLayout& layout,
                       const materials::MaterialList& materials, const NodeScalarField& mass,
                       const NodeVectorField& v_inertial, const boundary::NodeConstraints& constraints,
                       double dt);

  double dt() const { return dt_; }
  const grid::GridLayout& layout() const { return layout_; }
  const NodeScalarField& mass() const { return mass_; }
  const boundary::NodeConstraints& constraints() const { return constraints_; }

  /// A_p of particle p (in cell c) for grid velocities v.
  Mat3 particle_strain_increment(std::size_t c, std::size_t p, const NodeVectorField& v) const {
    return dt_ * layout_.gradient(c, p, v);
  }

  /// This rank's part of E(v).
  EnergyValue energy(const NodeVectorField& v) const;
  /// This rank's contributions to ∇E(v) on its local nodes (shared entries are partial sums),
  /// projected with P_i. Returns false if some particle is infeasible at v.
  bool gradient(const NodeVectorField& v, NodeVectorField& g) const;
  /// For every occupied cell, the element matrix Δt² Σ_p ∂²Φ_p/∂v² over the cell's stencil,
  /// with each particle's ∂²Φ_p/∂A² projected to PSD if `project`, and projected with P_i on both
  /// sides. The inertia M is not included: it is diagonal and owned, and the assembly adds it.
  void element_hessians(const NodeVectorField& v, bool project,
                        const std::function<void(std::size_t cell, const ElementMatrix&)>& sink) const;
  /// ∂²Φ_p/∂vec(A)² of every particle (projected if `project`), in particle order: the pieces a
  /// matrix-free Hessian applies.
  std::vector<Mat9> particle_hessians(const NodeVectorField& v, bool project) const;

 private:
  const materials::Material& material_of(std::size_t p) const;

  const particles::ParticleSet& particles_;
  const grid::GridLayout& layout_;
  const materials::MaterialList& materials_;
  const NodeScalarField& mass_;
  const NodeVectorField& v_inertial_;
  const boundary::NodeConstraints& constraints_;
  double dt_;
  std::vector<char> node_is_free_;
};

}  // namespace viscompm::implicit
