#include "viscompm/newton/linear_system.hpp"

#include "viscompm/linalg/newton_system.hpp"

namespace viscompm::newton {

namespace {
class SimulationSystem : public LinearSystem {
 public:
  explicit SimulationSystem(linalg::NewtonSystem& system) : system_(system) {}
  double assemble(const implicit::IncrementalPotential& potential, const NodeVectorField& v, bool project) override {
    return system_.assemble(potential, v, project);
  }
  double precondition() override { return system_.precondition(); }
  double prepare() override { return system_.prepare(); }
  linalg::LinearSolveReport solve(const NodeVectorField& rhs, NodeVectorField& dv, double tolerance,
                                  int max_iterations) override {
    return system_.solve(rhs, dv, tolerance, max_iterations);
  }
  void apply_preconditioner(const NodeVectorField& r, NodeVectorField& z) override { system_.apply_preconditioner(r, z); }
  bool unpreconditioned() const override { return !system_.has_preconditioner(); }
  std::uint64_t pattern_version() const override { return system_.pattern_version(); }
  double default_tolerance() const override { return system_.default_tolerance(); }
  bool matrix_free() const override { return system_.matrix_free(); }
  std::string label() const override { return system_.configuration().label(); }
  const linalg::NewtonSystem* newton_system() const override { return &system_; }

 private:
  linalg::NewtonSystem& system_;
};
}  // namespace

std::unique_ptr<LinearSystem> make_linear_system(linalg::NewtonSystem& system) {
  return std::make_unique<SimulationSystem>(system);
}

}  // namespace viscompm::newton
