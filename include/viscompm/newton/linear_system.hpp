// What Newton needs of its linear system: the seam between the minimiser and linalg/. The
// simulation's system is linalg::NewtonSystem (make_linear_system wraps it); tests drive the
// minimiser's control logic with systems of their own (e.g. one whose every solve fails).
#pragma once

#include <cstdint>
#include <memory>

#include "viscompm/implicit/incremental_potential.hpp"
#include "viscompm/linalg/linear_solver.hpp"

namespace viscompm::linalg {
class NewtonSystem;
}

namespace viscompm::newton {

class LinearSystem {
 public:
  virtual ~LinearSystem() = default;
  /// Assembles H at grid velocities v (particle Hessians projected to PSD if `project`); seconds.
  virtual double assemble(const implicit::IncrementalPotential& potential, const NodeVectorField& v, bool project) = 0;
  /// Sets the preconditioner up for the current H; seconds.
  virtual double precondition() = 0;
  /// Solves H dv = rhs to the relative residual `tolerance` with the current preconditioner, in at
  /// most `max_iterations` Krylov iterations (≤ 0: the solver file's limit).
  virtual linalg::LinearSolveReport solve(const NodeVectorField& rhs, NodeVectorField& dv, double tolerance,
                                          int max_iterations) = 0;
  /// z = P⁻¹ r: one application of the current preconditioner (the identity if there is none).
  virtual void apply_preconditioner(const NodeVectorField& r, NodeVectorField& z) = 0;
  /// True if there is no preconditioner (apply_preconditioner is the identity).
  virtual bool unpreconditioned() const = 0;
  /// Builds what the system needs on the current node space if it is not built yet (a measured
  /// choice's candidate builds its Hessian's graph when it is first used on a partition); seconds.
  virtual double prepare() { return 0.0; }
  /// Changes whenever the sparsity pattern is rebuilt.
  virtual std::uint64_t pattern_version() const = 0;
  /// The solver file's relative tolerance.
  virtual double default_tolerance() const = 0;
  virtual bool matrix_free() const = 0;
  /// The label of the solver configuration (solver.csv).
  virtual std::string label() const = 0;
  /// The simulation's system behind this one, if any (for observers that dump it).
  virtual const linalg::NewtonSystem* newton_system() const { return nullptr; }
};

/// The seam over the simulation's assembled or matrix-free system.
std::unique_ptr<LinearSystem> make_linear_system(linalg::NewtonSystem& system);

}  // namespace viscompm::newton
