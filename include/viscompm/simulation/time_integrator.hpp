// One time step of §5.5.1, in the order of the algorithm:
//   layout → p2g → objective → newton (assemble, precondition, cg, line search) → g2p → advect
// each phase under a named timer. A step whose Newton solve fails leaves the particles as they
// were, so the caller can retry with a smaller Δt.
#pragma once

#include <memory>

#include "viscompm/boundary/colliders.hpp"
#include "viscompm/grid/grid_layout.hpp"
#include "viscompm/implicit/newton.hpp"
#include "viscompm/linalg/newton_system.hpp"
#include "viscompm/linalg/node_space.hpp"
#include "viscompm/materials/material.hpp"
#include "viscompm/parallel/decomposition.hpp"
#include "viscompm/transfer/transfer.hpp"

namespace viscompm::simulation {

struct IntegratorSettings {
  Vec3 gravity = Vec3::Zero();
  bool delete_outside_particles = false;  ///< else clamp them to the last cell
  transfer::TransferSettings transfer;
  implicit::NewtonSettings newton;
};

/// The objective of one step, built from the last p2g (valid until the next build_layout).
struct StepObjective {
  NodeVectorField v_star;                   ///< v^n + Δt g
  boundary::NodeConstraints constraints;    ///< colliders at time t
  NodeVectorField initial_guess;            ///< v* with constraints applied
  std::unique_ptr<implicit::IncrementalPotential> potential;
};

struct StepReport {
  double dt = 0.0;
  implicit::NewtonReport newton;
  bool graph_rebuilt = false;
  std::size_t particles_clamped = 0;
  std::size_t particles_deleted = 0;
  std::size_t particles_sent = 0;   ///< migrated to other ranks by this rank
  std::size_t shared_nodes = 0;     ///< nodes this rank holds but does not own (ghosts)
  std::size_t owned_nodes = 0;
};

class TimeIntegrator {
 public:
  TimeIntegrator(const parallel::Communicator& comm, const grid::GridGeometry& geometry, grid::KernelOrder order,
                 const parallel::Decomposition& decomposition, const IntegratorSettings& settings,
                 const materials::MaterialList& materials, const boundary::Boundary& boundary,
                 const linalg::SolverConfiguration& solver);

  /// Advances `particles` from time t by dt. If Newton fails, particles are unchanged (only
  /// reordered) and the report says why. A non-empty `dump_prefix` writes the first Newton
  /// system to PREFIX.mtx / PREFIX_rhs.mtx.
  StepReport step(particles::ParticleSet& particles, double t, double dt, const std::string& dump_prefix = "");

  // The phases of step(), public for tests and the solver study.
  /// Sorts particles by cell and decides node ownership for this step.
  void build_layout(particles::ParticleSet& particles);
  /// Grid mass and velocity v^n, summed over ranks.
  void particles_to_grid(const particles::ParticleSet& particles);
  /// E(v) of the step from t to t + dt.
  std::unique_ptr<StepObjective> build_objective(const particles::ParticleSet& particles, double t, double dt) const;
  /// Particle velocities, affine velocities and strains from the solved grid velocities.
  void grid_to_particles(particles::ParticleSet& particles, const NodeVectorField& v, double dt);
  /// Moves particles, keeps them in the grid, sends them to their new owners.
  void advect(particles::ParticleSet& particles, double dt, StepReport& report);

  const IntegratorSettings& settings() const { return settings_; }
  /// Node ownership from now on (after rebalancing; the particles must be migrated to it).
  void set_decomposition(const parallel::Decomposition& decomposition) { decomposition_ = &decomposition; }
  const grid::GridLayout& layout() const { return layout_; }
  linalg::NewtonSystem& newton_system() { return system_; }
  linalg::NodeSpace& node_space() { return space_; }
  /// Grid mass and velocity of the last p2g, on the layout's local nodes.
  const NodeScalarField& grid_mass() const { return mass_; }
  const NodeVectorField& grid_velocity() const { return v_old_; }

 private:
  parallel::Communicator comm_;
  grid::GridLayout layout_;
  const parallel::Decomposition* decomposition_;
  IntegratorSettings settings_;
  const materials::MaterialList& materials_;
  const boundary::Boundary& boundary_;
  linalg::NodeSpace space_;
  linalg::NewtonSystem system_;
  NodeScalarField mass_;
  NodeVectorField momentum_, v_old_;
};

}  // namespace viscompm::simulation
