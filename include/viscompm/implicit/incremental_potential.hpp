// The objective of the implicit step (§5.5, the optimisation form of Gast et al. 2015 that §5.7
// uses; doc/numerics.md):
//   E(v) = Σ_i ½ m_i |v_i − v_i^*|² + Σ_p Φ_p(A_p(v)),  A_p = Δt Σ_i v_i (∇w_ip)^T,
// with v^* = v^n + Δt g. Owner computes: this rank's energy is that of its own particles and
// owned nodes (sums across ranks are the caller's), while gradients and Hessians are complete on
// the owned nodes, from the own particles and the ghost copies of neighbours' particles.
// Constrained components (colliders) are fixed: gradients and Hessian blocks are projected with P_i.
#pragma once

#include <Eigen/Core>
#include <functional>
#include <limits>

#include "viscompm/boundary/colliders.hpp"
#include "viscompm/grid/grid_layout.hpp"
#include "viscompm/implicit/element_hessian.hpp"
#include "viscompm/materials/material.hpp"

namespace viscompm::implicit {

struct EnergyValue {
  double value = 0.0;      ///< E on this rank (+∞ if a particle's state is infeasible)
  double magnitude = 0.0;  ///< Σ |terms|: the scale of rounding errors in `value`
  bool feasible() const { return value < std::numeric_limits<double>::infinity(); }
};

class IncrementalPotential {
 public:
  /// `mass` and `v_inertial` are the grid mass and v^n + Δt g on all local nodes; `particles`
  /// holds the own particles then the ghosts, as binned in `layout`.
  IncrementalPotential(const particles::ParticleSet& particles, const grid::GridLayout& layout,
                       const materials::MaterialList& materials, const NodeScalarField& mass,
                       const NodeVectorField& v_inertial, const boundary::NodeConstraints& constraints,
                       double dt);

  double dt() const { return dt_; }
  const grid::GridLayout& layout() const { return layout_; }
  /// The particles (own, then ghosts, as binned in layout()) and their materials.
  const particles::ParticleSet& particles() const { return particles_; }
  const materials::MaterialList& materials() const { return materials_; }
  const NodeScalarField& mass() const { return mass_; }
  const boundary::NodeConstraints& constraints() const { return constraints_; }

  /// A_p of particle p (in cell c) for grid velocities v.
  Mat3 particle_strain_increment(std::size_t c, std::size_t p, const NodeVectorField& v) const {
    return dt_ * layout_.gradient(c, p, v);
  }

  /// This rank's part of E(v): its own particles and owned nodes.
  EnergyValue energy(const NodeVectorField& v) const;
  /// ∇E(v) on the owned nodes (complete), projected with P_i; zero on ghost nodes. Returns false
  /// if some particle is infeasible at v.
  bool gradient(const NodeVectorField& v, NodeVectorField& g) const;
  /// For every occupied cell (own and ghost), the element Δt² Σ_p ∂²Φ_p/∂v² over the cell's
  /// stencil, each particle's ∂²Φ_p/∂A² projected to PSD if `project`. The inertia M is not
  /// included (the assembly adds it); read the blocks through constrained_block.
  void element_hessians(const NodeVectorField& v, bool project,
                        const std::function<void(std::size_t cell, const ElementHessian&)>& sink) const;
  /// Block (a, b), a ≤ b, of cell c's element with the constraints applied, P_i B P_j for the
  /// cell's stencil nodes i, j; diagonal blocks exactly symmetric.
  Mat3 constrained_block(const ElementHessian& element, std::size_t c, int a, int b) const;
  /// Δt² ∂²Φ_p/∂vec(A)² of every particle, own and ghost (projected if `project`), in particle
  /// order: the pieces a matrix-free Hessian applies.
  std::vector<Mat9> particle_hessians(const NodeVectorField& v, bool project) const;
  /// True if no stencil node of cell c has a constraint (its element blocks need no P_i).
  bool cell_is_free(std::size_t c) const;
  /// True where node i (local index) has no constraint.
  bool is_free(std::size_t i) const { return node_is_free_[i] != 0; }

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
