#include "viscompm/transfer/transfer.hpp"

#include "viscompm/core/error.hpp"

namespace viscompm::transfer {

void particles_to_grid(const particles::ParticleSet& particles, const grid::GridLayout& layout,
                       Scheme scheme, NodeScalarField& mass, NodeVectorField& momentum) {
  mass.assign(layout.local_node_count(), 0.0);
  momentum.assign(layout.local_node_count(), Vec3::Zero());
  const bool affine = scheme == Scheme::apic;
  const int owned = static_cast<int>(layout.owned_count);
  for (std::size_t c = 0; c < layout.cell_count(); ++c) {
    for (std::size_t p = layout.cell_begin[c]; p < layout.cell_begin[c + 1]; ++p) {
      const double m = particles.mass[p];
      const Vec3& x = particles.position[p];
      const Vec3& v = particles.velocity[p];
      const Mat3& C = particles.affine_velocity[p];
      grid::for_each_stencil_node(layout, c, p, [&](int, int i, double w, const Vec3&) {
        if (i >= owned) return;
        mass[i] += w * m;
        Vec3 vi = v;
        if (affine) vi += C * (layout.geometry.node_position(layout.nodes[i]) - x);
        momentum[i] += (w * m) * vi;
      });
    }
  }
}

NodeVectorField grid_velocity(const NodeScalarField& mass, const NodeVectorField& momentum) {
  NodeVectorField v(mass.size(), Vec3::Zero());
  for (std::size_t i = 0; i < mass.size(); ++i)
    if (mass[i] > 0.0) v[i] = momentum[i] / mass[i];
  return v;
}

std::vector<Mat3> grid_to_particles(particles::ParticleSet& particles, const grid::GridLayout& layout,
                                    const TransferSettings& settings, const NodeVectorField& v_new,
                                    const NodeVectorField& v_old, double dt) {
  std::vector<Mat3> A(layout.own_particle_count());
  const double inverse_inertia =
      1.0 / (grid::apic_inertia_factor(layout.order) * layout.geometry.dx * layout.geometry.dx);
  for (std::size_t c = 0; c < layout.own_cell_count; ++c) {
    for (std::size_t p = layout.cell_begin[c]; p < layout.cell_begin[c + 1]; ++p) {
      const Vec3& x = particles.position[p];
      Vec3 v_pic = Vec3::Zero(), dv = Vec3::Zero();
      Mat3 B = Mat3::Zero(), grad_v = Mat3::Zero();
      grid::for_each_stencil_node(layout, c, p, [&](int, int i, double w, const Vec3& dw) {
        v_pic += w * v_new[i];
        dv += w * (v_new[i] - v_old[i]);
        grad_v += v_new[i] * dw.transpose();
        B += w * v_new[i] * (layout.geometry.node_position(layout.nodes[i]) - x).transpose();
      });
      if (settings.scheme == Scheme::apic) {
        particles.velocity[p] = v_pic;
        particles.affine_velocity[p] = B * inverse_inertia;
      } else {
        // v_p = (1 − α) v_PIC + α (v_p + Δv_FLIP), §3.4.
        particles.velocity[p] =
            (1.0 - settings.flip_ratio) * v_pic + settings.flip_ratio * (particles.velocity[p] + dv);
      }
      A[p] = dt * grad_v;
    }
  }
  return A;
}

}  // namespace viscompm::transfer
