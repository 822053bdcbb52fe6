// Newton on the incremental potential: quadratic convergence near the solution on a smooth
// elastic case, free fall under gravity against the exact discrete and continuous motion, and
// every Newton strategy (Hessian and preconditioner reuse, inexact Newton) reaching the state of
// exact Newton to the Newton tolerance while doing less work; a stop request on one rank ending
// the solve on every rank.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <memory>
#include <string>

#include "gather.hpp"
#include "scenes.hpp"
#include "viscompm/simulation/simulation.hpp"

using namespace viscompm;

namespace {
// A soft elastic block spinning and stretching: a nonlinear step at a large Δt, ready for Newton.
class NewtonOnASpinningBlock : public ::testing::Test {
 protected:
  static scene::SceneConfig spinning_block() {
    auto scene = testkit::base_scene(Vec3(1.0, 1.0, 1.0), 0.1);
    scene.materials.push_back(testkit::oldroyd_b_material("rubber", 1.0, 20.0, 50.0, 0.0, "physical", 1e6));
    auto body = testkit::box_body("rubber", Vec3(0.3, 0.3, 0.3), Vec3(0.7, 0.7, 0.7), Vec3::Zero());
    body.angular_velocity = Vec3(0.0, 0.0, 6.0);
    scene.bodies.push_back(body);
    scene.newton.tolerance = 1e-13;
    scene.newton.max_iterations = 40;
    return scene;
  }
  NewtonOnASpinningBlock()
      : comm(MPI_COMM_WORLD), scene(spinning_block()), sim(scene, testkit::jacobi_cg(1e-13), comm) {
    sim.integrator().prepare(sim.particles(), dt);
    objective = sim.integrator().build_objective(sim.particles(), 0.0, dt);
    v = objective->initial_guess;
  }
  static constexpr double dt = 0.02;
  const parallel::Communicator comm;
  const scene::SceneConfig scene;
  simulation::Simulation sim;
  std::unique_ptr<simulation::StepObjective> objective;
  NodeVectorField v;
};
}  // namespace

TEST_F(NewtonOnASpinningBlock, ConvergesQuadraticallyNearTheSolution) {
  newton::NewtonSolver solver(scene.newton, sim.integrator().newton_system(), comm);
  const auto report = solver.solve(*objective->potential, v);
  ASSERT_TRUE(report.converged) << report.failure;
  const auto& r = report.residual_history;
  ASSERT_GE(r.size(), 4u) << "the case should need several Newton iterations";
  // Quadratic: once in the basin (r_k < 1e-2 r_0), r_{k+1} ≤ C r_k² / r_0 until rounding.
  int quadratic_steps = 0;
  for (std::size_t k = 0; k + 1 < r.size(); ++k) {
    if (r[k] > 1e-2 * r[0] || r[k + 1] < 1e-11 * r[0]) continue;
    EXPECT_LT(r[k + 1] / r[0], 10.0 * (r[k] / r[0]) * (r[k] / r[0])) << "iteration " << k;
    ++quadratic_steps;
  }
  EXPECT_GE(quadratic_steps, 1);
  EXPECT_EQ(report.backtracks, 0);
}

TEST_F(NewtonOnASpinningBlock, AStopRequestOnOneRankEndsTheSolveOnEveryRankAfterTheIterationsBeforeIt) {
  // The last rank asks to stop before the third iteration.
  newton::NewtonSolver solver(scene.newton, sim.integrator().newton_system(), comm);
  int asked = 0;
  solver.set_interrupt([&] { return ++asked == 3 && comm.rank() == comm.size() - 1; });
  const auto report = solver.solve(*objective->potential, v);
  EXPECT_TRUE(report.interrupted);
  EXPECT_FALSE(report.converged);
  EXPECT_EQ(report.iterations, 2);
  EXPECT_EQ(report.residual_history.size(), 3u);
  EXPECT_EQ(asked, 3);
}

namespace {
// The simulation's system, except that every linear solve fails: CG reports no convergence and an
// ascent direction. Counts what Newton asks of it.
class FailingSystem : public newton::LinearSystem {
 public:
  explicit FailingSystem(linalg::NewtonSystem& system) : real_(newton::make_linear_system(system)) {}
  double assemble(const implicit::IncrementalPotential& potential, const NodeVectorField& v, bool project) override {
    ++assemblies;
    projected_assemblies += project;
    last_projected = project;
    assembly_kinds += project ? 'p' : 'e';
    calls += 'A';
    return real_->assemble(potential, v, project);
  }
  double precondition() override {
    ++setups;
    calls += 'P';
    return real_->precondition();
  }
  linalg::LinearSolveReport solve(const NodeVectorField& rhs, NodeVectorField& dv, double tolerance,
                                  int max_iterations) override {
    ++solves;
    calls += 'S';
    if (!failing || (fail_exact_only && last_projected)) return real_->solve(rhs, dv, tolerance, max_iterations);
    dv.resize(rhs.size());
    for (std::size_t i = 0; i < rhs.size(); ++i) dv[i] = -rhs[i];  // +∇E: uphill
    linalg::LinearSolveReport report;
    report.iterations = 7;
    report.converged = false;
    report.tolerance = tolerance;
    return report;
  }
  void apply_preconditioner(const NodeVectorField& r, NodeVectorField& z) override { real_->apply_preconditioner(r, z); }
  bool unpreconditioned() const override { return real_->unpreconditioned(); }
  std::uint64_t pattern_version() const override { return real_->pattern_version(); }
  double default_tolerance() const override { return real_->default_tolerance(); }
  bool matrix_free() const override { return real_->matrix_free(); }
  std::string label() const override { return "failing"; }

  bool failing = true;
  bool fail_exact_only = false;  // fail only the solves of an H assembled unprojected
  bool last_projected = false;
  std::string assembly_kinds;  // in order: e exact, p projected
  int assemblies = 0, projected_assemblies = 0, setups = 0, solves = 0;
  std::string calls;  // in order: A assembly, P preconditioner set-up, S solve

 private:
  std::unique_ptr<newton::LinearSystem> real_;
};
}  // namespace

TEST_F(NewtonOnASpinningBlock, WhenEverySolveFailsEachDirectionEndsAfterAtMostThreeAttempts) {
  // The strategies that keep H or its preconditioner: a kept one that fails is replaced by a fresh
  // one, an exact H that fails by the projected one, and then Newton gives up — for the first
  // direction of a step (nothing kept yet: fresh exact, then fresh projected) and for one whose H
  // and preconditioner were kept from an earlier step (kept, fresh exact, fresh projected).
  for (const char* update : {"every step", "lagged"}) {
    newton::NewtonSettings settings = scene.newton;
    settings.hessian_projection = newton::HessianProjection::adaptive;
    settings.hessian_update = newton::HessianUpdate::lagged;
    settings.preconditioner_update =
        std::string(update) == "lagged" ? newton::PreconditionerUpdate::lagged : newton::PreconditionerUpdate::every_step;
    FailingSystem failing(sim.integrator().newton_system());
    newton::NewtonSolver solver(settings, failing, comm);
    NodeVectorField v_first = v;
    const auto first = solver.solve(*objective->potential, v_first);
    EXPECT_FALSE(first.converged) << update;
    EXPECT_EQ(first.iterations, 1) << update;
    EXPECT_EQ(failing.solves, 2) << update;
    EXPECT_EQ(failing.projected_assemblies, 1) << update;
    EXPECT_EQ(first.linear_solves.size(), 2u) << update;
    EXPECT_FALSE(first.failure.empty()) << update;

    // H and the preconditioner kept from a successful solve, then failures.
    newton::NewtonSolver keeping(settings, failing, comm);
    failing.failing = false;
    NodeVectorField v_converged = v;
    ASSERT_TRUE(keeping.solve(*objective->potential, v_converged).converged) << update;
    // Whether the kept preconditioner was set up from the kept H: a lagged H re-assembled within
    // the converged step (a shortened line-search step, a slow contraction: rounding decides) is
    // preconditioned again at the next step's first attempt under "every step", not under "lagged".
    const bool preconditioner_matches = failing.calls.find_last_of('A') < failing.calls.find_last_of('P');
    const std::string kept_attempt = std::string(update) == "every step" && !preconditioner_matches ? "PS" : "S";
    failing.failing = true;
    failing.solves = failing.assemblies = failing.projected_assemblies = failing.setups = 0;
    failing.calls.clear();
    NodeVectorField v_kept = v;
    const auto second = keeping.solve(*objective->potential, v_kept);
    EXPECT_FALSE(second.converged) << update;
    EXPECT_EQ(second.iterations, 1) << update;
    EXPECT_EQ(failing.solves, newton::NewtonSolver::direction_attempts) << update;
    EXPECT_EQ(failing.projected_assemblies, 1) << update;
    // The kept H (no assembly), then a fresh exact and a fresh projected H, each preconditioned.
    EXPECT_EQ(failing.calls, kept_attempt + "APS" + "APS") << update;
  }
}

TEST_F(NewtonOnASpinningBlock, AnExactHessianFailingWithAKeptPreconditionerIsProjectedUnderThatPreconditioner) {
  // Adaptive projection, H fresh at every iteration, the preconditioner set up once per step: when
  // the exact H fails with the kept preconditioner (built for another H), the projected H is tried
  // with that same preconditioner — it is SPD, so CG needs no new one — before anything is set up
  // again. Every exact solve fails here: the first direction sets up twice (exact, then projected:
  // nothing was kept), every later one is the exact attempt and the projected one, no set-up.
  newton::NewtonSettings settings = scene.newton;
  settings.hessian_projection = newton::HessianProjection::adaptive;
  settings.hessian_update = newton::HessianUpdate::every_iteration;
  settings.preconditioner_update = newton::PreconditionerUpdate::every_step;
  FailingSystem exact_fails(sim.integrator().newton_system());
  exact_fails.fail_exact_only = true;
  newton::NewtonSolver solver(settings, exact_fails, comm);
  const auto report = solver.solve(*objective->potential, v);
  ASSERT_TRUE(report.converged) << report.failure;
  ASSERT_GE(report.iterations, 3);
  std::string expected = "APSAPS";
  for (int k = 1; k < report.iterations; ++k) expected += "ASAS";
  EXPECT_EQ(exact_fails.calls.substr(0, expected.size()), expected);
  EXPECT_EQ(exact_fails.setups, 2);
  EXPECT_EQ(report.preconditioner_setups, 2);
}

TEST_F(NewtonOnASpinningBlock, AfterAnExactHessianFailedAtAStepsStartLaterStepsStartProjected) {
  // Adaptive projection: the exact H failed as the first direction of a step, so the next step's
  // first direction assembles the projected H at once (an exact assembly, set-up and failed solve
  // spared) and its later directions try the exact H again; forget() (a failed step, a
  // checkpoint) returns to the exact start, so that a restart repeats the run.
  newton::NewtonSettings settings = scene.newton;
  settings.hessian_projection = newton::HessianProjection::adaptive;
  FailingSystem exact_fails(sim.integrator().newton_system());
  exact_fails.fail_exact_only = true;
  newton::NewtonSolver solver(settings, exact_fails, comm);
  NodeVectorField v_first = v;
  ASSERT_TRUE(solver.solve(*objective->potential, v_first).converged);
  EXPECT_EQ(exact_fails.assembly_kinds.substr(0, 2), "ep") << "the first step starts exact";
  exact_fails.assembly_kinds.clear();
  NodeVectorField v_second = v;
  const auto second = solver.solve(*objective->potential, v_second);
  ASSERT_TRUE(second.converged);
  ASSERT_GE(second.iterations, 2);
  EXPECT_EQ(exact_fails.assembly_kinds.substr(0, 3), "pep") << "projected first, then the exact H tried again";
  solver.forget();
  exact_fails.assembly_kinds.clear();
  NodeVectorField v_third = v;
  ASSERT_TRUE(solver.solve(*objective->potential, v_third).converged);
  EXPECT_EQ(exact_fails.assembly_kinds.substr(0, 2), "ep") << "after forget() a step starts exact again";
}

TEST_F(NewtonOnASpinningBlock, AStopRequestBetweenAttemptsEndsTheSolve) {
  newton::NewtonSettings settings = scene.newton;
  settings.hessian_projection = newton::HessianProjection::adaptive;
  FailingSystem failing(sim.integrator().newton_system());
  newton::NewtonSolver solver(settings, failing, comm);
  int asked = 0;
  solver.set_interrupt([&] { return ++asked == 2; });  // after the first attempt of the first direction
  const auto report = solver.solve(*objective->potential, v);
  EXPECT_TRUE(report.interrupted);
  EXPECT_EQ(failing.solves, 1);
  EXPECT_EQ(asked, 2);
}

TEST(Newton, FreeFallMatchesTheExactMotion) {
  const Vec3 g(0.0, -9.81, 0.0), v0(0.5, 1.0, -0.25), lower(0.8, 1.6, 0.8);
  auto scene = testkit::base_scene(Vec3(2.0, 2.4, 2.0), 0.1);
  scene.simulation.gravity = g;
  scene.materials.push_back(testkit::oldroyd_b_material("block", 2.0, 100.0, 300.0, 0.1, "physical", 1.0));
  scene.bodies.push_back(testkit::box_body("block", lower, lower + Vec3(0.4, 0.4, 0.4), v0));
  const double T = 0.25, dt = 0.025;
  scene.simulation.max_time_step = dt;
  const parallel::Communicator comm(MPI_COMM_WORLD);
  simulation::Simulation sim(scene, testkit::jacobi_cg(1e-12), comm);
  // Initial positions of all particles (they may change rank: migration, rebalancing).
  const auto initial = testkit::gather_particles(sim.particles(), comm.comm());
  simulation::RunSummary summary;
  sim.advance_to(T, summary);
  EXPECT_EQ(summary.steps, 10);
  auto& ps = sim.particles();
  double worst_velocity = 0.0, worst_discrete = 0.0, worst_continuous = 0.0;
  for (std::size_t p = 0; p < ps.size(); ++p) {
    // Symplectic Euler (x += Δt v^{n+1}) falls ½ g T Δt further than the continuous motion.
    const Vec3 continuous = initial.at(ps.id[p]).x + v0 * T + 0.5 * g * T * T;
    const Vec3 discrete = continuous + 0.5 * g * T * dt;
    worst_velocity = std::max(worst_velocity, (ps.velocity[p] - (v0 + g * T)).norm());
    worst_discrete = std::max(worst_discrete, (ps.position[p] - discrete).norm());
    worst_continuous = std::max(worst_continuous, (ps.position[p] - continuous).norm());
    EXPECT_LT((ps.deformation_gradient[p] - Mat3::Identity()).norm(), 1e-9);  // no strain
  }
  EXPECT_LT(comm.max(worst_velocity), 1e-9);
  EXPECT_LT(comm.max(worst_discrete), 1e-9);
  EXPECT_NEAR(comm.max(worst_continuous), 0.5 * g.norm() * T * dt, 1e-9);
}

namespace {
struct StrategyRun {
  std::map<ParticleId, testkit::ParticleState> state;
  std::int64_t newton_iterations = 0, cg_iterations = 0, assemblies = 0, setups = 0;
};

// The default scene, coarse, for a few steps through the bullet's impact, with `settings` over
// exact Newton and the assembled Jacobi-CG (pinned here: the scene's own defaults may be faster
// strategies).
StrategyRun run_sponge(const std::vector<scene::Override>& newton_settings, const std::string& solver_file = "") {
  std::vector<scene::Override> overrides = {{"Grid/Cell size", "0.06"}, {"Newton/Tolerance", "1e-7"},
                                            {"Newton/Linear tolerance", "fixed"},
                                            {"Newton/Hessian update", "every iteration"}};
  overrides.insert(overrides.end(), newton_settings.begin(), newton_settings.end());
  const auto scene = scene::read_scene(VISCOMPM_SOURCE_DIR "/inputs/scenes/shooting_sponge.xml", overrides);
  const parallel::Communicator comm(MPI_COMM_WORLD);
  simulation::Simulation sim(
      scene,
      linalg::SolverConfiguration::read(solver_file.empty() ? VISCOMPM_SOURCE_DIR "/inputs/solvers/jacobi_cg.xml" : solver_file),
      comm);
  StrategyRun run;
  simulation::RunSummary summary;
  sim.advance_to(0.06, summary);
  run.newton_iterations = summary.newton_iterations;
  run.cg_iterations = summary.linear_iterations;
  run.assemblies = summary.assemblies;
  run.setups = summary.preconditioner_setups;
  run.state = testkit::gather_particles(sim.particles(), comm.comm());
  return run;
}
}  // namespace

TEST(Newton, EveryStrategyReachesTheStateOfExactNewtonWithLessWork) {
  const StrategyRun exact = run_sponge({});
  EXPECT_GE(exact.assemblies, exact.newton_iterations) << "exact Newton assembles at every iteration";
  struct Case {
    std::string name;
    std::vector<scene::Override> settings;
  };
  const std::vector<Case> cases = {
      {"Hessian once per step", {{"Newton/Hessian update", "every step"}}},
      {"lagged Hessian", {{"Newton/Hessian update", "lagged"}}},
      {"lagged preconditioner", {{"Newton/Preconditioner update", "lagged"}}},
      {"inexact Newton", {{"Newton/Linear tolerance", "eisenstat-walker"}}},
      // HOT's quasi-Newton: the preconditioner of H, assembled once per step, as its initial inverse.
      {"L-BFGS", {{"Newton/Method", "L-BFGS"}, {"Newton/Max iterations", "400"}}},
  };
  for (const Case& c : cases) {
    const StrategyRun run = run_sponge(c.settings);
    // The same trajectory to the Newton tolerance (1e-7 Δx/Δt in velocity, over a few steps).
    EXPECT_LT(testkit::max_state_difference(exact.state, run.state), 1e-5) << c.name;
    if (c.name == "inexact Newton") EXPECT_LT(run.cg_iterations, exact.cg_iterations) << c.name;
    else if (c.name == "lagged preconditioner") EXPECT_LT(run.setups, exact.setups) << c.name;
    else if (c.name == "L-BFGS") {
      EXPECT_EQ(run.cg_iterations, run.newton_iterations) << "one preconditioner application per direction";
      EXPECT_LT(run.assemblies, exact.assemblies) << c.name;
    }
    else EXPECT_LT(run.assemblies, exact.assemblies) << c.name;
  }
}

TEST(Newton, AHierarchyReusedAcrossIterationsAndStepsReachesTheStateOfAFreshOne) {
  const std::string gmg = VISCOMPM_SOURCE_DIR "/inputs/solvers/gmg_cg.xml";
  const StrategyRun fresh = run_sponge({}, gmg);
  for (const char* update : {"every step", "lagged"}) {
    const StrategyRun reused = run_sponge({{"Newton/Preconditioner update", update}}, gmg);
    EXPECT_LT(testkit::max_state_difference(fresh.state, reused.state), 1e-5) << update;
    EXPECT_LT(reused.setups, fresh.setups) << update;
  }
}

TEST_F(NewtonOnASpinningBlock, AnIterationBoundBelowOneEndsTheSolveWithoutADirection) {
  // Max iterations is read as at least 1, but a caller in code may set anything: the loop is
  // counted, so 0 or −1 directions end the solve after testing the initial residual once.
  for (int bound : {0, -1}) {
    newton::NewtonSettings settings = scene.newton;
    settings.max_iterations = bound;
    newton::NewtonSolver solver(settings, sim.integrator().newton_system(), comm);
    NodeVectorField v_try = v;
    const auto report = solver.solve(*objective->potential, v_try);
    EXPECT_EQ(report.iterations, 0) << bound;
    EXPECT_FALSE(report.converged) << bound;
    EXPECT_EQ(report.residual_history.size(), 1u) << bound;
    EXPECT_NE(report.failure.find("no convergence in " + std::to_string(bound) + " iterations"), std::string::npos)
        << report.failure;
  }
}

TEST_F(NewtonOnASpinningBlock, EveryPreconditionerSetUpGoesThroughTheSeamAndIsCounted) {
  // The system never sets its preconditioner up by itself: a solve before any set-up is a
  // contract violation, and in a Newton solve the set-ups the seam sees are the ones reported.
  auto& system = sim.integrator().newton_system();
  NodeVectorField rhs(v.size(), Vec3::UnitX()), dv;
  system.assemble(*objective->potential, v, true);
  EXPECT_THROW(system.solve(rhs, dv), std::logic_error);
  EXPECT_THROW(system.apply_preconditioner(rhs, dv), std::logic_error);
  FailingSystem counting(system);
  counting.failing = false;
  newton::NewtonSolver solver(scene.newton, counting, comm);
  const auto report = solver.solve(*objective->potential, v);
  ASSERT_TRUE(report.converged) << report.failure;
  EXPECT_GE(counting.setups, 1);
  EXPECT_EQ(counting.setups, report.preconditioner_setups);
  EXPECT_EQ(counting.assemblies, report.assemblies);
}
