// Particle ↔ grid transfers of §3.1/§3.4: APIC (Jiang et al. 2015, used by the paper's scenes,
// §5.6) and the PIC/FLIP blend of §3.4. Grid fields are on the layout's local nodes. Owner
// computes: p2g sums own and ghost particles into the owned nodes (complete there; the caller
// imports the ghost nodes' values), g2p updates the own particles.
#pragma once

#include <string>
#include <vector>

#include "viscompm/grid/grid_layout.hpp"
#include "viscompm/particles/particle_set.hpp"

namespace viscompm::transfer {

enum class Scheme { apic, pic_flip };

struct TransferSettings {
  Scheme scheme = Scheme::apic;
  double flip_ratio = 0.95;  ///< α of §3.4 (PIC/FLIP only)
};

/// m_i = Σ_p m_p w_ip and (m v)_i = Σ_p m_p w_ip (v_p + C_p (x_i − x_p)) (C_p = 0 for PIC/FLIP)
/// on the owned nodes; zero on ghost nodes.
void particles_to_grid(const particles::ParticleSet& particles, const grid::GridLayout& layout,
                       Scheme scheme, NodeScalarField& mass, NodeVectorField& momentum);

/// Grid velocities from summed mass and momentum: v_i = (m v)_i / m_i (0 where m_i = 0).
NodeVectorField grid_velocity(const NodeScalarField& mass, const NodeVectorField& momentum);

/// Updates v_p (and C_p for APIC) of the own particles from the new grid velocities (on all
/// local nodes), and returns per own particle the A_p = Δt Σ_i v_i (∇w_ip)^T that advances its
/// strains. v_old is the p2g velocity (FLIP).
std::vector<Mat3> grid_to_particles(particles::ParticleSet& particles, const grid::GridLayout& layout,
                                    const TransferSettings& settings, const NodeVectorField& v_new,
                                    const NodeVectorField& v_old, double dt);

}  // namespace viscompm::transfer
