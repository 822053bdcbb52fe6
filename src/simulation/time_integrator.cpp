#include "viscompm/simulation/time_integrator.hpp"

#include <Teuchos_TimeMonitor.hpp>

#include <cmath>
#include <type_traits>
#include <utility>

#include "viscompm/parallel/ghost_particles.hpp"
#include "viscompm/parallel/migration.hpp"
#include "viscompm/particles/binning.hpp"

namespace viscompm::simulation {

namespace {
Teuchos::RCP<Teuchos::Time> timer(const char* name) { return Teuchos::TimeMonitor::getNewCounter(name); }

// One Newton system per configuration: the solver file's, or each of a measured choice's.
std::vector<std::unique_ptr<linalg::NewtonSystem>> make_systems(const linalg::NodeSpace& space,
                                                                const linalg::SolverConfiguration& solver) {
  std::vector<std::unique_ptr<linalg::NewtonSystem>> systems;
  if (!solver.is_choice()) systems.push_back(std::make_unique<linalg::NewtonSystem>(space, solver));
  for (const auto& candidate : solver.candidates()) systems.push_back(std::make_unique<linalg::NewtonSystem>(space, candidate));
  return systems;
}
std::vector<linalg::NewtonSystem*> pointers(const std::vector<std::unique_ptr<linalg::NewtonSystem>>& systems) {
  std::vector<linalg::NewtonSystem*> out;
  for (const auto& s : systems) out.push_back(s.get());
  return out;
}
}  // namespace

TimeIntegrator::TimeIntegrator(const parallel::Communicator& comm, const grid::GridGeometry& geometry,
                               grid::KernelOrder order, const parallel::Decomposition& decomposition,
                               const IntegratorSettings& settings, const materials::MaterialList& materials,
                               const boundary::Boundary& boundary, const linalg::SolverConfiguration& solver)
    : comm_(comm),
      decomposition_(&decomposition),
      settings_(settings),
      materials_(materials),
      boundary_(boundary),
      space_(comm),
      systems_(make_systems(space_, solver)),
      newton_(solver.is_choice()
                  ? newton::NewtonSolver(settings.newton, pointers(systems_), solver.choice(), comm)
                  : newton::NewtonSolver(settings.newton, *systems_.front(), comm)) {
  layout_.geometry = geometry;
  layout_.order = order;
}

StepReport TimeIntegrator::step(particles::ParticleSet& own_particles, double t, double dt,
                                 const std::optional<std::string>& dump_prefix) {
  static const auto layout_timer = timer("viscompm: 1 layout");
  static const auto p2g_timer = timer("viscompm: 2 p2g");
  static const auto newton_timer = timer("viscompm: 3 newton");
  static const auto g2p_timer = timer("viscompm: 4 g2p");
  static const auto advect_timer = timer("viscompm: 5 advect");
  StepReport report;
  report.dt = dt;
  particles::ParticleSet& particles = working_;
  particles = own_particles;  // the caller's set changes only if the step is taken
  {
    Teuchos::TimeMonitor m(*layout_timer);
    report.partition_rebuilt = build_layout(particles, dt);
    report.ghost_particles = particles.size() - layout_.own_particle_count();
  }
  report.owned_nodes = layout_.owned_count;
  report.shared_nodes = layout_.local_node_count() - layout_.owned_count;
  {
    Teuchos::TimeMonitor m(*p2g_timer);
    particles_to_grid(particles);
  }
  const std::unique_ptr<StepObjective> objective = build_objective(particles, t, dt);
  NodeVectorField v = objective->initial_guess;
  {
    Teuchos::TimeMonitor m(*newton_timer);
    newton::SystemObserver dump;
    if (dump_prefix)
      dump = [&](int iteration, const linalg::NewtonSystem& system, const NodeVectorField& rhs) {
        // The first Newton iteration's H is assembled at the initial guess.
        if (iteration == 1) system.write_matrix_market(*dump_prefix, *objective->potential, objective->initial_guess, rhs);
      };
    report.newton = newton_.solve(*objective->potential, v, dump);
  }
  drop_ghosts(particles);
  if (report.newton.interrupted) return report;
  if (!report.newton.converged) {
    report.failure = "Newton failed (" + report.newton.failure + ")";
    return report;
  }
  {
    Teuchos::TimeMonitor m(*g2p_timer);
    grid_to_particles(particles, v, dt);
    // Particle-based collisions (§5.5.1): no particle crosses a collider between nodes.
    boundary_.collide_particles(particles.position, particles.velocity, t, dt);
  }
  {
    Teuchos::TimeMonitor m(*advect_timer);
    advect(particles, dt, report);
  }
  if (!finite(particles)) {
    report.failure = "the step produced non-finite particle values";
    return report;
  }
  std::swap(own_particles, working_);
  report.taken = true;
  return report;
}

bool TimeIntegrator::finite(const particles::ParticleSet& particles) const {
  bool finite = true;
  particles.for_each_field([&](const char*, const auto& field) {
    using T = typename std::decay_t<decltype(field)>::value_type;
    if constexpr (std::is_same_v<T, Vec3> || std::is_same_v<T, Mat3>) {
      for (const auto& value : field) finite &= value.allFinite();
    } else if constexpr (std::is_same_v<T, double>) {
      for (double value : field) finite &= std::isfinite(value);
    }
  });
  return !comm_.any(!finite);
}

std::unique_ptr<StepObjective> TimeIntegrator::build_objective(const particles::ParticleSet& particles, double t,
                                                               double dt) const {
  // Inertia toward v* = v^n + Δt g; colliders fix the constrained components; the initial
  // guess is v* with the constraints applied.
  auto objective = std::make_unique<StepObjective>();
  objective->v_star.resize(v_old_.size());
  for (std::size_t i = 0; i < v_old_.size(); ++i) objective->v_star[i] = v_old_[i] + dt * settings_.gravity;
  objective->constraints = boundary_.constrain(layout_, t, objective->v_star);
  objective->initial_guess = objective->v_star;
  objective->constraints.apply(objective->initial_guess);
  objective->potential = std::make_unique<implicit::IncrementalPotential>(
      particles, layout_, materials_, mass_, objective->v_star, objective->constraints, dt);
  // Newton needs a feasible start (E < ∞). Where v* is not, the velocities of time n often are.
  if (comm_.any(!objective->potential->energy(objective->initial_guess).feasible())) {
    NodeVectorField previous = v_old_;
    objective->constraints.apply(previous);
    if (!comm_.any(!objective->potential->energy(previous).feasible())) objective->initial_guess = previous;
  }
  return objective;
}

namespace {
// Each occupied cell padded by the margin, and further along its particles' displacement over
// the lookahead steps (capped), so that the partition outlives the motion it can see.
std::vector<parallel::PaddedCell> padded_cells(const particles::ParticleSet& particles, const grid::GridLayout& layout,
                                               const PaddingSettings& padding, double dt) {
  std::vector<parallel::PaddedCell> cells(layout.own_cell_count);
  const double reach = padding.lookahead * dt / layout.geometry.dx;
  for (std::size_t c = 0; c < layout.own_cell_count; ++c) {
    Vec3 lowest = Vec3::Zero(), highest = Vec3::Zero();
    for (std::size_t p = layout.cell_begin[c]; p < layout.cell_begin[c + 1]; ++p) {
      lowest = lowest.cwiseMin(reach * particles.velocity[p]);
      highest = highest.cwiseMax(reach * particles.velocity[p]);
    }
    cells[c].cell = layout.cells[c];
    for (int d = 0; d < 3; ++d) {
      cells[c].pad_below[d] = padding.margin + std::min(padding.max_padding, static_cast<int>(std::ceil(-lowest[d])));
      cells[c].pad_above[d] = padding.margin + std::min(padding.max_padding, static_cast<int>(std::ceil(highest[d])));
    }
  }
  return cells;
}
}  // namespace

bool TimeIntegrator::build_layout(particles::ParticleSet& particles, double dt) {
  particles::bin_particles(particles, 0, layout_);
  layout_.own_cell_count = layout_.cells.size();
  // A new partition when a particle's stencil left the current one, or ownership changed.
  const bool rebuild = partition_ == nullptr || partition_decomposition_ != decomposition_ ||
                       comm_.any(!partition_->covers(layout_.cells, 0, layout_.own_cell_count));
  if (rebuild) {
    partition_ = std::make_unique<parallel::NodePartition>(comm_, layout_.geometry, layout_.order, *decomposition_,
                                                           padded_cells(particles, layout_, settings_.padding, dt));
    partition_decomposition_ = decomposition_;
    ++partition_builds_;
    space_.update(*partition_);
    newton_system().build_pattern();
    layout_.nodes = partition_->nodes();
    layout_.owned_count = partition_->owned_count();
  }
  // Owner computes: the neighbours' particles that reach owned nodes, binned after the own ones.
  const std::size_t own = particles.size();
  parallel::append_ghost_particles(comm_, *partition_, layout_, particles);
  particles::bin_particles(particles, own, layout_);
  partition_->index_cells(layout_.cells, 0, layout_.cell_count(), layout_.cell_nodes);
  return rebuild;
}

bool TimeIntegrator::first_right_hand_side(const StepObjective& objective, NodeVectorField& rhs) const {
  if (comm_.any(!objective.potential->gradient(objective.initial_guess, rhs))) return false;
  for (Vec3& r : rhs) r = -r;
  return true;
}

void TimeIntegrator::drop_ghosts(particles::ParticleSet& particles) const {
  particles.resize(layout_.own_particle_count());
}

void TimeIntegrator::particles_to_grid(const particles::ParticleSet& particles) {
  transfer::particles_to_grid(particles, layout_, settings_.transfer.scheme, mass_, momentum_);
  v_old_ = transfer::grid_velocity(mass_, momentum_);
  space_.import_ghosts(mass_);
  space_.import_ghosts(v_old_);
}

void TimeIntegrator::grid_to_particles(particles::ParticleSet& particles, const NodeVectorField& v, double dt) {
  const std::vector<Mat3> A = transfer::grid_to_particles(particles, layout_, settings_.transfer, v, v_old_, dt);
  const materials::StepContext step{dt};
  for (std::size_t p = 0; p < A.size(); ++p)
    materials_[particles.material_id[p]]->update_state(particles, p, A[p], step);
}

void TimeIntegrator::advect(particles::ParticleSet& particles, double dt, StepReport& report) {
  for (std::size_t p = 0; p < particles.size(); ++p) particles.position[p] += dt * particles.velocity[p];
  if (settings_.delete_outside_particles)
    report.particles_deleted = boundary_.delete_outside_particles(layout_.geometry, particles);
  else
    report.particles_clamped = boundary_.clamp_particles(layout_.geometry, particles.position);
  report.particles_sent = parallel::migrate_particles(comm_, *decomposition_, layout_.geometry, layout_.order, particles);
}

}  // namespace viscompm::simulation
