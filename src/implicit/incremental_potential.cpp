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
  for (std::size_t c = 0; c < layout_.cell_count(); ++c) {
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
  for (std::size_t c = 0; c < layout_.cell_count(); ++c) {
    for (std::size_t p = layout_.cell_begin[c]; p < layout_.cell_begin[c + 1]; ++p) {
      if (!material_of(p).evaluate(particles_, p, particle_strain_increment(c, p, v), step, 1, piece))
        return false;
      // ∂Φ_p/∂v_i = Δt (∂Φ_p/∂A) ∇w_ip.
      const Mat3 scaled = dt_ * piece.gradient;
      grid::for_each_stencil_node(layout_, c, p,
                                  [&](int, int i, double, const Vec3& dw) { g[i] += scaled * dw; });
    }
  }
  for (std::size_t i = 0; i < layout_.owned_count; ++i) g[i] += mass_[i] * (v[i] - v_inertial_[i]);
  constraints_.project(g);
  return true;
}

void IncrementalPotential::element_hessians(
    const NodeVectorField& v, bool project,
    const std::function<void(std::size_t, const ElementMatrix&)>& sink) const {
  const int K = layout_.nodes_per_cell();
  const materials::StepContext step{dt_};
  materials::PotentialDerivatives piece;
  ElementMatrix element(3 * K, 3 * K);
  Eigen::Matrix<double, 9, Eigen::Dynamic> HG(9, 3 * K);
  std::vector<Vec3> dw(K);
  for (std::size_t c = 0; c < layout_.cell_count(); ++c) {
    element.setZero();
    for (std::size_t p = layout_.cell_begin[c]; p < layout_.cell_begin[c + 1]; ++p) {
      if (!material_of(p).evaluate(particles_, p, particle_strain_increment(c, p, v), step, 2, piece))
        throw SimulationError("Hessian requested at an infeasible state");
      if (project) materials::project_to_psd(piece.hessian);
      const Mat9 H = dt_ * dt_ * piece.hessian;
      grid::for_each_stencil_node(layout_, c, p, [&](int k, int, double, const Vec3& g) { dw[k] = g; });
      // vec(A)[σ + 3β] = Δt Σ_j v_jσ ∇w_j[β]: with D(3i+σ, σ+3β) = ∇w_i[β], the particle's
      // block is D H Dᵀ. HD = H Dᵀ column by column, then E += D HD column by column.
      for (int j = 0; j < K; ++j)
        for (int tau = 0; tau < 3; ++tau)
          HG.col(3 * j + tau) = H.col(tau) * dw[j][0] + H.col(tau + 3) * dw[j][1] + H.col(tau + 6) * dw[j][2];
      // Upper block triangle only (node i ≤ node j); mirrored once per cell below.
      for (int j = 0; j < K; ++j)
        for (int tau = 0; tau < 3; ++tau) {
          const int col = 3 * j + tau;
          const Vec3 h0 = HG.col(col).segment<3>(0), h1 = HG.col(col).segment<3>(3), h2 = HG.col(col).segment<3>(6);
          double* e = element.col(col).data();
          for (int i = 0; i <= j; ++i) {
            const Vec3 block = dw[i][0] * h0 + dw[i][1] * h1 + dw[i][2] * h2;
            e[3 * i] += block[0];
            e[3 * i + 1] += block[1];
            e[3 * i + 2] += block[2];
          }
        }
    }
    // Mirror: the element is exactly symmetric.
    for (int j = 0; j < K; ++j) {
      const Mat3 diagonal = element.block<3, 3>(3 * j, 3 * j);
      element.block<3, 3>(3 * j, 3 * j) = 0.5 * (diagonal + diagonal.transpose());
      for (int i = 0; i < j; ++i) element.block<3, 3>(3 * j, 3 * i) = element.block<3, 3>(3 * i, 3 * j).transpose();
    }
    // Fixed components: P_i H_ij P_j.
    const int* nodes = layout_.nodes_of_cell(c);
    for (int i = 0; i < K; ++i) {
      if (node_is_free_[nodes[i]]) continue;
      const Mat3& P = constraints_.projection[nodes[i]];
      for (int j = 0; j < K; ++j) {
        element.block<3, 3>(3 * i, 3 * j) = P * element.block<3, 3>(3 * i, 3 * j);
        element.block<3, 3>(3 * j, 3 * i) = element.block<3, 3>(3 * j, 3 * i) * P;
      }
    }
    sink(c, element);
  }
}

std::vector<Mat9> IncrementalPotential::particle_hessians(const NodeVectorField& v, bool project) const {
  std::vector<Mat9> hessians(particles_.size());
  const materials::StepContext step{dt_};
  materials::PotentialDerivatives piece;
  for (std::size_t c = 0; c < layout_.cell_count(); ++c)
    for (std::size_t p = layout_.cell_begin[c]; p < layout_.cell_begin[c + 1]; ++p) {
      if (!material_of(p).evaluate(particles_, p, particle_strain_increment(c, p, v), step, 2, piece))
        throw SimulationError("Hessian requested at an infeasible state");
      if (project) materials::project_to_psd(piece.hessian);
      hessians[p] = piece.hessian;
    }
  return hessians;
}

}  // namespace viscompm::implicit
