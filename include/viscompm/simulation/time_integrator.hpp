// One time step of §5.5.1, in the order of the algorithm:
//   layout → p2g → objective → newton (assemble, precondition, cg, line search) → g2p → advect
// each phase under a named timer. The step works on the integrator's own copy of the particles
// (with the neighbours' ghost particles appended to it, not to the caller's set) and replaces the
// caller's particles only when it succeeds: a failed step (Newton, or a non-finite value) is
// undone here, in one place, and the caller retries with a smaller Δt.
#pragma once

#include <memory>
#include <optional>
#include <vector>
#include <string>

#include "viscompm/boundary/colliders.hpp"
#include "viscompm/grid/grid_layout.hpp"
#include "viscompm/newton/newton_solver.hpp"
#include "viscompm/linalg/newton_system.hpp"
#include "viscompm/linalg/node_space.hpp"
#include "viscompm/materials/material.hpp"
#include "viscompm/parallel/decomposition.hpp"
#include "viscompm/parallel/node_partition.hpp"
#include "viscompm/transfer/transfer.hpp"

namespace viscompm::simulation {

/// How far the node partition (the Hessian's graph) reaches beyond the occupied cells.
struct PaddingSettings {
  int margin = 0;              ///< cells around every occupied cell
  double lookahead = 8.0;      ///< and further along each particle's velocity: this many steps
  int max_padding = 8;         ///< cap on the velocity padding, in cells
};

struct IntegratorSettings {
  Vec3 gravity = Vec3::Zero();
  PaddingSettings padding;
  bool delete_outside_particles = false;  ///< else clamp them to the last cell (Grid/Outside particles)
  transfer::TransferSettings transfer;
  newton::NewtonSettings newton;
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
  bool taken = false;               ///< the particles were advanced (else they are as they were)
  std::string failure;              ///< why not (empty when taken or interrupted)
  newton::NewtonReport newton;
  bool partition_rebuilt = false;   ///< the node partition (and the Hessian's graph) was built anew
  std::size_t ghost_particles = 0;  ///< neighbours' particles copied here
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

  /// Advances `particles` from time t by dt (collective). They change only when the step is
  /// taken: if Newton fails or is interrupted, or the step leaves a non-finite value on any rank,
  /// they stay exactly as they were and the report says why. With a `dump_prefix`, the first
  /// Newton system is written to PREFIX.mtx / PREFIX_rhs.mtx.
  StepReport step(particles::ParticleSet& particles, double t, double dt,
                  const std::optional<std::string>& dump_prefix = std::nullopt);

  // The phases of step(), public for tests and the solver study (step() runs them on its own
  // copy of the particles; called directly, they work on the set they are given).
  /// Sorts particles by cell, rebuilds the node partition if a particle left it (padding for
  /// steps of `dt`), and appends the ghost particles to `particles` (drop_ghosts removes them).
  /// Returns true if the partition was rebuilt.
  bool build_layout(particles::ParticleSet& particles, double dt);
  /// Drops what steps reuse (the node partition, the Hessian's graph, a kept Hessian and
  /// preconditioner), as a run
  /// restarted at this point starts: called after each checkpoint, so that restarts continue bit
  /// for bit (the padding decides the vector lengths, and so the grouping of floating-point sums).
  void reset_reuse() {
    partition_.reset();
    newton_.forget();
  }
  /// build_layout and particles_to_grid: what tests, benchmarks and the solver study need before
  /// build_objective.
  void prepare(particles::ParticleSet& particles, double dt) {
    build_layout(particles, dt);
    particles_to_grid(particles);
  }
  /// The first Newton right-hand side −∇E at the objective's initial guess, on the owned nodes
  /// (zero on ghosts). False on every rank if the initial guess is infeasible (collective).
  bool first_right_hand_side(const StepObjective& objective, NodeVectorField& rhs) const;
  /// Removes the ghost particles build_layout appended.
  void drop_ghosts(particles::ParticleSet& particles) const;
  /// Grid mass and velocity v^n on the local nodes (complete on owned nodes, imported to ghosts).
  void particles_to_grid(const particles::ParticleSet& particles);
  /// E(v) of the step from t to t + dt.
  std::unique_ptr<StepObjective> build_objective(const particles::ParticleSet& particles, double t, double dt) const;
  /// Velocities, affine velocities and strains of the own particles from the solved grid velocities.
  void grid_to_particles(particles::ParticleSet& particles, const NodeVectorField& v, double dt);
  /// Moves particles, keeps them in the grid, sends them to their new owners.
  void advect(particles::ParticleSet& particles, double dt, StepReport& report);

  const IntegratorSettings& settings() const { return settings_; }
  /// Node ownership from now on (after rebalancing; the particles must be migrated to it). The
  /// next step rebuilds the node partition.
  void set_decomposition(const parallel::Decomposition& decomposition) { decomposition_ = &decomposition; }
  const grid::GridLayout& layout() const { return layout_; }
  /// The system the next Newton direction is computed with (a measured choice's next candidate).
  linalg::NewtonSystem& newton_system() { return *systems_[newton_.candidate()]; }
  /// Newton's solve ends early (the step is not taken) when `requested` is true on any rank.
  void set_interrupt(std::function<bool()> requested) { newton_.set_interrupt(std::move(requested)); }
  /// A measured choice's state (null for one solver configuration).
  const newton::SolverChoice* solver_choice() const { return newton_.choice(); }
  linalg::NodeSpace& node_space() { return space_; }
  /// How many times the node partition has been built.
  int partition_builds() const { return partition_builds_; }
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
  std::unique_ptr<parallel::NodePartition> partition_;
  const parallel::Decomposition* partition_decomposition_ = nullptr;  // the decomposition it was built for
  int partition_builds_ = 0;
  linalg::NodeSpace space_;
  // One Newton system per solver configuration: one, or a measured choice's candidates (each
  // builds its Hessian's graph when it is first used on a partition).
  std::vector<std::unique_ptr<linalg::NewtonSystem>> systems_;
  newton::NewtonSolver newton_;
  NodeScalarField mass_;
  NodeVectorField momentum_, v_old_;
  particles::ParticleSet working_;  ///< the particles of the step in progress, ghosts appended

  /// True on every rank if no rank holds a non-finite particle value.
  bool finite(const particles::ParticleSet& particles) const;
};

}  // namespace viscompm::simulation
