#include "viscompm/implicit/incremental_potential.hpp"

#include <cmath>

#include "viscompm/core/error.hpp"
#include "viscompm/materials/psd_projection.hpp"

namespace viscompm::implicit {

IncrementalPotential::IncrementalPotential(const particles::ParticleSet& particles,
                                           const grid::GridLayout& layout,
                                           const materials::MaterialList& materials,
                                           const NodeScalarField& mass, const NodeVectorField& v_inertial,
                                           const boundary::NodeConstraints& constraints, double dt)
    : particles_(particles),
      layout_(layout),
      materials_(materials),
      mass_(mass),
      v_inertial_(v_inertial),
      constraints_(constraints),
      dt_(dt) {
  node_is_free_.resize(layout.local_node_count());
  for (std::size_t i = 0; i < node_is_free_.size(); ++i)
    node_is_free_[i] = constraints.projection[i] == Mat3::Identity();
}

const materials::Material& IncrementalPotential::material_of(std::size_t p) const {
  return *materials_[particles_.material_id[p]];
}

EnergyValue IncrementalPotential::energy(const NodeVectorField& v) const {
  EnergyValue e;
  const materials::StepContext step{dt_};
  materials::PotentialDerivatives piece;
  for (std::size_t c = 0; c < layout_.own_cell_count; ++c) {
    for (std::size_t p = layout_.cell_begin[c]; p < layout_.cell_begin[c + 1]; ++p) {
      if (!material_of(p).evaluate(particles_, p, particle_strain_increment(c, p, v), step, 0, piece)) {
        e.value = std::numeric_limits<double>::infinity();
        return e;
      }
      e.value += piece.energy;
      e.magnitude += std::abs(piece.energy);
    }
  }
  // Inertia of owned nodes: ½ m_i |v_i − v_i^*|².
  for (std::size_t i = 0; i < layout_.owned_count; ++i) {
    const double kinetic = 0.5 * mass_[i] * (v[i] - v_inertial_[i]).squaredNorm();
    e.value += kinetic;
    e.magnitude += kinetic;
  }
  return e;
}

bool IncrementalPotential::gradient(const NodeVectorField& v, NodeVectorField& g) const {
  g.assign(layout_.local_node_count(), Vec3::Zero());
  const materials::StepContext step{dt_};
  materials::PotentialDerivatives piece;
  const int owned = static_cast<int>(layout_.owned_count);
  for (std::size_t c = 0; c < layout_.cell_count(); ++c) {
    for (std::size_t p = layout_.cell_begin[c]; p < layout_.cell_begin[c + 1]; ++p) {
      if (!material_of(p).evaluate(particles_, p, particle_strain_increment(c, p, v), step, 1, piece))
        return false;
      // ∂Φ_p/∂v_i = Δt (∂Φ_p/∂A) ∇w_ip, on owned nodes.
      const Mat3 scaled = dt_ * piece.gradient;
      grid::for_each_stencil_node(layout_, c, p, [&](int, int i, double, const Vec3& dw) {
        if (i < owned) g[i] += scaled * dw;
      });
    }
  }
  for (std::size_t i = 0; i < layout_.owned_count; ++i) g[i] += mass_[i] * (v[i] - v_inertial_[i]);
  constraints_.project(g);
  return true;
}

void IncrementalPotential::element_hessians(
    const NodeVectorField& v, bool project,
    const std::function<void(std::size_t, const ElementHessian&)>& sink) const {
  const int K = layout_.nodes_per_cell();
  const materials::StepContext step{dt_};
  const double dt2 = dt_ * dt_;
  materials::PotentialDerivatives piece;
  ElementHessian element(K);
  std::vector<Vec3> dw(K);
  for (std::size_t c = 0; c < layout_.cell_count(); ++c) {
    element.clear();
    for (std::size_t p = layout_.cell_begin[c]; p < layout_.cell_begin[c + 1]; ++p) {
      if (!material_of(p).evaluate(particles_, p, particle_strain_increment(c, p, v), step, 2, piece))
        throw SimulationError("Hessian requested at an infeasible state");
      if (project) materials::project_to_psd(piece.hessian);
      grid::for_each_stencil_node(layout_, c, p, [&](int k, int, double, const Vec3& g) { dw[k] = g; });
      element.add_particle(dt2 * piece.hessian, dw.data());
    }
    sink(c, element);
  }
}

bool IncrementalPotential::cell_is_free(std::size_t c) const {
  const int* nodes = layout_.nodes_of_cell(c);
  for (int k = 0; k < layout_.nodes_per_cell(); ++k)
    if (!node_is_free_[nodes[k]]) return false;
  return true;
}

Mat3 IncrementalPotential::constrained_block(const ElementHessian& element, std::size_t c, int a, int b) const {
  Mat3 B = element.block(a, b);
  if (a == b) B = 0.5 * (B + B.transpose());
  const int* nodes = layout_.nodes_of_cell(c);
  if (!node_is_free_[nodes[a]]) B = constraints_.projection[nodes[a]] * B;
  if (!node_is_free_[nodes[b]]) B = B * constraints_.projection[nodes[b]];
  return B;
}

std::vector<Mat9> IncrementalPotential::particle_hessians(const NodeVectorField& v, bool project) const {
  std::vector<Mat9> hessians(particles_.size());
  const materials::StepContext step{dt_};
  const double dt2 = dt_ * dt_;
  materials::PotentialDerivatives piece;
  for (std::size_t c = 0; c < layout_.cell_count(); ++c)
    for (std::size_t p = layout_.cell_begin[c]; p < layout_.cell_begin[c + 1]; ++p) {
      if (!material_of(p).evaluate(particles_, p, particle_strain_increment(c, p, v), step, 2, piece))
        throw SimulationError("Hessian requested at an infeasible state");
      if (project) materials::project_to_psd(piece.hessian);
      hessians[p] = dt2 * piece.hessian;
    }
  return hessians;
}

}  // namespace viscompm::implicit
