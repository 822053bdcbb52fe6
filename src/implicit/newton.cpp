#include "viscompm/implicit/newton.hpp"

#include <Teuchos_TimeMonitor.hpp>
#include <cmath>
#include <iomanip>
#include <sstream>

namespace viscompm::implicit {

const ParameterTable<NewtonSettings>& NewtonSettings::table() {
  static const ParameterTable<NewtonSettings> t = [] {
    ParameterTable<NewtonSettings> table;
    using N = NewtonSettings;
    table.integer(&N::max_iterations, "Max iterations", 20, Range::at_least(1), "Newton iterations per step before Δt is halved")
        .real(&N::tolerance, "Tolerance", 1e-6, Range::positive(),
              "converged when the mass-weighted residual velocity is below Tolerance·Δx/Δt")
        .integer(&N::max_line_search_steps, "Max line search steps", 20, Range::at_least(1),
                 "halvings of the step before the line search gives up")
        .real(&N::armijo, "Armijo constant", 1e-4, Range::open_closed(0.0, 0.5),
              "sufficient decrease: E(v + α dv) ≤ E(v) + c α ∇E·dv")
        .string(&N::hessian_projection, "Hessian projection", "adaptive", {"always", "adaptive", "never"},
                "clamp each particle's ∂²Φ/∂A² to PSD so the matrix is SPD: always, or only when the exact "
                "Hessian fails (CG meets negative curvature, no descent, no decrease), or never");
    return table;
  }();
  return t;
}

namespace {
struct GlobalEnergy {
  double value;
  double magnitude;
};

GlobalEnergy global_energy(const IncrementalPotential& potential, const NodeVectorField& v,
                           const parallel::Communicator& comm) {
  const EnergyValue local = potential.energy(v);
  const bool infeasible = comm.any(!local.feasible());
  if (infeasible) return {std::numeric_limits<double>::infinity(), 0.0};
  return {comm.sum(local.value), comm.sum(local.magnitude)};
}

double owned_dot(const NodeVectorField& a, const NodeVectorField& b, std::size_t owned,
                 const parallel::Communicator& comm) {
  double local = 0.0;
  for (std::size_t i = 0; i < owned; ++i) local += a[i].dot(b[i]);
  return comm.sum(local);
}
}  // namespace

double velocity_residual(const IncrementalPotential& potential, const NodeVectorField& g,
                         const parallel::Communicator& comm) {
  double weighted = 0.0, mass = 0.0;
  for (std::size_t i = 0; i < potential.layout().owned_count; ++i) {
    const double m = potential.mass()[i];
    if (m <= 0.0) continue;
    weighted += g[i].squaredNorm() / m;
    mass += m;
  }
  const double total_mass = comm.sum(mass);
  return total_mass > 0.0 ? std::sqrt(comm.sum(weighted) / total_mass) : 0.0;
}

NewtonReport newton_solve(const IncrementalPotential& potential, const linalg::NodeSpace& space,
                          linalg::NewtonSystem& system, const NewtonSettings& settings, NodeVectorField& v,
                          const SystemObserver& observer) {
  static const auto assemble_timer = Teuchos::TimeMonitor::getNewCounter("viscompm: 3a newton assemble");
  static const auto line_search_timer = Teuchos::TimeMonitor::getNewCounter("viscompm: 3d newton line search");
  static const auto gradient_timer = Teuchos::TimeMonitor::getNewCounter("viscompm: 3e newton gradient");
  const auto& comm = space.comm();
  const std::size_t owned = potential.layout().owned_count;
  NewtonReport report;
  report.tolerance = settings.tolerance * potential.layout().geometry.dx / potential.dt();

  NodeVectorField g, dv, v_trial;
  // Backtracking line search on E along dv (§5.7: E = +∞ where b_OB or F becomes infeasible).
  // On success v moves to v + α dv.
  auto line_search = [&](double slope) {
    Teuchos::TimeMonitor timer(*line_search_timer);
    const GlobalEnergy e0 = global_energy(potential, v, comm);
    double alpha = 1.0;
    for (int k = 0; k < settings.max_line_search_steps; ++k, alpha *= 0.5) {
      v_trial = v;
      for (std::size_t i = 0; i < v.size(); ++i) v_trial[i] += alpha * dv[i];
      const GlobalEnergy e = global_energy(potential, v_trial, comm);
      // Allow rounding of E itself: its terms cancel to within ~1e-13 of their magnitude.
      if (e.value <= e0.value + settings.armijo * alpha * slope + 1e-12 * e0.magnitude) {
        report.step_lengths.push_back(alpha);
        v.swap(v_trial);
        return true;
      }
      ++report.backtracks;
    }
    return false;
  };
  for (;;) {
    {
      Teuchos::TimeMonitor timer(*gradient_timer);
      const bool feasible = potential.gradient(v, g);
      if (comm.any(!feasible)) {
        report.failure = "infeasible state";
        return report;
      }
    }
    report.residual = velocity_residual(potential, g, comm);
    report.residual_history.push_back(report.residual);
    if (!std::isfinite(report.residual)) {
      report.failure = "residual is not finite";
      return report;
    }
    if (report.residual <= report.tolerance) {
      report.converged = true;
      return report;
    }
    if (report.iterations == settings.max_iterations) {
      report.failure = "no convergence in " + std::to_string(settings.max_iterations) + " iterations";
      return report;
    }
    ++report.iterations;

    // Newton direction: H dv = −∇E. In adaptive mode the exact Hessian is tried first; its
    // PSD-projected version is used when CG meets negative curvature, or the exact direction
    // is not a descent direction or gives no decrease.
    for (Vec3& x : g) x = -x;
    bool projected = settings.hessian_projection == "always";
    const bool may_project = settings.hessian_projection != "never";
    for (;;) {
      {
        Teuchos::TimeMonitor timer(*assemble_timer);
        system.assemble(potential, v, projected);
      }
      if (observer) observer(report.iterations, system, g);
      report.linear_solves.push_back(system.solve(g, dv));
      report.projected_solves += projected;
      potential.constraints().project(dv);
      const double slope = -owned_dot(g, dv, owned, comm);  // ∇E·dv
      const bool usable = slope < 0.0 && (report.linear_solves.back().converged || projected || !may_project);
      if (usable && line_search(slope)) break;
      if (projected || !may_project) {
        report.failure = usable ? "line search found no decrease" : "the linear solve gave no descent direction";
        return report;
      }
      projected = true;
    }
  }
}

std::string NewtonReport::history() const {
  std::ostringstream out;
  out << std::setprecision(2) << "residual/tolerance";
  for (double r : residual_history) out << ' ' << r / tolerance;
  out << "; step lengths";
  for (double a : step_lengths) out << ' ' << a;
  return out.str();
}

}  // namespace viscompm::implicit
