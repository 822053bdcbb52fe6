// Every solver configuration in inputs/solvers/ solves a small sponge Newton system on 1 and 2
// ranks with the same iteration count (±10 %); the stiff multigrid files solve a stiff-inclusion
// system (contrast 10⁴ at the frame time step) with the same counts on any rank count; a
// multigrid hierarchy refreshed for a ten times stiffer matrix on the same pattern (reusing what it
// kept) is still an SPD preconditioner; and the matrix-free Hessian equals the assembled one on
// random vectors.
#include <gtest/gtest.h>

#include <filesystem>
#include <cmath>
#include <fstream>
#include <random>
#include <sstream>

#include "gather.hpp"
#include "scenes.hpp"
#include "viscompm/simulation/simulation.hpp"

using namespace viscompm;

namespace {
std::vector<std::string> solver_files() {
  std::vector<std::string> files;
  for (const auto& e : std::filesystem::directory_iterator(VISCOMPM_SOURCE_DIR "/inputs/solvers"))
    if (e.path().extension() == ".xml") files.push_back(e.path().string());
  std::sort(files.begin(), files.end());
  return files;
}


// A Newton system of the small sponge with moving parts at a Δt of several elastic CFL limits,
// solved from zero with `config`; returns the report of the solve.
linalg::LinearSolveReport solve_sponge_system(const linalg::SolverConfiguration& config,
                                              const parallel::Communicator& comm) {
  simulation::Simulation sim(testkit::sponge_scene(), config, comm);
  auto& integrator = sim.integrator();
  integrator.prepare(sim.particles(), 4e-3);
  const auto objective = integrator.build_objective(sim.particles(), 0.0, 4e-3);
  NodeVectorField g;
  EXPECT_TRUE(integrator.first_right_hand_side(*objective, g));
  auto& system = integrator.newton_system();
  system.assemble(*objective->potential, objective->initial_guess, true);
  system.precondition();
  NodeVectorField dv;
  return system.solve(g, dv);
}
}  // namespace

TEST(SolverConfigurations, EverySolverFileConvergesWithTheSameIterationsOnOneRankAndAll) {
  const parallel::Communicator world(MPI_COMM_WORLD);
  const auto files = solver_files();
  ASSERT_GE(files.size(), 8u);
  for (const auto& file : files) {
    const auto config = linalg::SolverConfiguration::read(file);
    const auto report = solve_sponge_system(config, world);
    EXPECT_TRUE(report.converged) << file;
    EXPECT_LT(report.relative_residual, 1e-5) << file;
    EXPECT_GT(report.iterations, 0) << file;
    int reference_iterations = report.iterations;
    if (MPI_Comm solo = testkit::solo_communicator(); solo != MPI_COMM_NULL) {
      reference_iterations = solve_sponge_system(config, parallel::Communicator(solo)).iterations;
      MPI_Comm_free(&solo);
    }
    MPI_Bcast(&reference_iterations, 1, MPI_INT, 0, MPI_COMM_WORLD);
    if (config.label().find("sgs") != std::string::npos) {
      // Ifpack2's Gauss-Seidel is hybrid: Gauss-Seidel within a rank, Jacobi between ranks. It
      // cannot match one rank; it must stay between true SGS and Jacobi (45 iterations here).
      EXPECT_GE(report.iterations, reference_iterations) << file;
      EXPECT_LT(report.iterations, 1.5 * reference_iterations) << file;
    } else {
      EXPECT_NEAR(report.iterations, reference_iterations, 0.1 * reference_iterations + 1)
          << file << ": " << world.size() << " ranks vs 1";
    }
    if (world.is_root())
      std::cout << "  " << config.label() << ": " << report.iterations << " iterations (1 rank: "
                << reference_iterations << ")\n";
  }
}

namespace {
std::string solver_file(const std::string& name) { return VISCOMPM_SOURCE_DIR "/inputs/solvers/" + name; }

// The first Newton system (PSD-projected) of the stiff-inclusion scene at its frame time step.
struct StiffSystem {
  explicit StiffSystem(const linalg::SolverConfiguration& config, const parallel::Communicator& comm)
      : scene(scene::read_scene(VISCOMPM_SOURCE_DIR "/inputs/scenes/stiff_inclusions.xml")),
        sim(scene, config, comm) {}
  // Assembles H at Δt (graph and objective of that Δt; the particle Hessians PSD-projected unless
  // told not to) and sets its preconditioner up.
  void assemble(double dt, bool project = true) {
    auto& integrator = sim.integrator();
    integrator.prepare(sim.particles(), dt);
    objective = integrator.build_objective(sim.particles(), 0.0, dt);
    ASSERT_TRUE(integrator.first_right_hand_side(*objective, rhs));
    integrator.newton_system().assemble(*objective->potential, objective->initial_guess, project);
    integrator.newton_system().precondition();
  }
  linalg::LinearSolveReport solve(int max_iterations = 0) {
    NodeVectorField dv;
    return sim.integrator().newton_system().solve(rhs, dv, 0.0, max_iterations);
  }
  scene::SceneConfig scene;
  simulation::Simulation sim;
  std::unique_ptr<simulation::StepObjective> objective;
  NodeVectorField rhs;
};
}  // namespace

TEST(SolverConfigurations, ASolveCappedByTheMeasuredChoiceStopsThereAndTheNextIsNot) {
  // The measured choice's budget caps one solve's iterations (NewtonSolver, SolverChoice): that
  // solve stops unconverged at the cap, and the solver file's own limit holds for the next one.
  const parallel::Communicator world(MPI_COMM_WORLD);
  StiffSystem system(linalg::SolverConfiguration::read(solver_file("matrix_free_jacobi_cg.xml")), world);
  system.assemble(1.0 / 24.0);
  const auto full = system.solve();
  ASSERT_TRUE(full.converged);
  ASSERT_GT(full.iterations, 10);
  const auto capped = system.solve(7);
  EXPECT_EQ(capped.iterations, 7);
  EXPECT_FALSE(capped.converged);
  EXPECT_GT(capped.relative_residual, full.relative_residual);
  const auto again = system.solve();
  EXPECT_TRUE(again.converged);
  EXPECT_EQ(again.iterations, full.iterations);
}

TEST(SolverConfigurations, TheStiffMultigridFilesSolveAStiffInclusionSystemOnAnyRankCount) {
  const parallel::Communicator world(MPI_COMM_WORLD);
  for (const char* name : {"muelu_lines_cg.xml", "gmg_lines_cg.xml", "line_jacobi_cg.xml"}) {
    const auto config = linalg::SolverConfiguration::read(solver_file(name));
    auto solve = [&](const parallel::Communicator& comm) {
      StiffSystem system(config, comm);
      system.assemble(1.0 / 24.0);
      return system.solve();
    };
    const auto report = solve(world);
    EXPECT_TRUE(report.converged) << name;
    EXPECT_LT(report.relative_residual, 1e-5) << name;
    int reference_iterations = report.iterations;
    if (MPI_Comm solo = testkit::solo_communicator(); solo != MPI_COMM_NULL) {
      reference_iterations = solve(parallel::Communicator(solo)).iterations;
      MPI_Comm_free(&solo);
    }
    MPI_Bcast(&reference_iterations, 1, MPI_INT, 0, MPI_COMM_WORLD);
    if (std::string(name) == "gmg_lines_cg.xml") {
      EXPECT_NEAR(report.iterations, reference_iterations, 0.1 * reference_iterations + 1)
          << name << ": " << world.size() << " ranks vs 1";
    } else {
      // A fine-level smoother of grid lines only: Ifpack2's blocks are rank-local, so lines are cut
      // at rank boundaries (doc/solvers.md) and the count may grow, by at most 20% per doubling.
      EXPECT_GE(report.iterations, 0.9 * reference_iterations) << name;
      EXPECT_LE(report.iterations, reference_iterations * (1.0 + 0.2 * std::log2(world.size())) + 1)
          << name << ": " << world.size() << " ranks vs 1";
    }
    if (world.is_root())
      std::cout << "  stiff inclusions, " << config.label() << ": " << report.iterations << " iterations (1 rank: "
                << reference_iterations << ")\n";
  }
}

TEST(SolverConfigurations, AHierarchyRefreshedForATenTimesStifferMatrixIsStillSpd) {
  // H = M + Δt² K: the same graph at √10 Δt has ten times the stiffness. The set-up for the
  // second matrix reuses what the first one kept (MueLu's reuse, the geometric prolongators, the
  // line blocks); CG must still converge — a stale Chebyshev bound or damping would not.
  const parallel::Communicator world(MPI_COMM_WORLD);
  for (const char* name : {"muelu_cg.xml", "gmg_cg.xml", "gmg_aggregates_cg.xml", "muelu_lines_cg.xml",
                           "gmg_lines_cg.xml", "line_jacobi_cg.xml"}) {
    StiffSystem system(linalg::SolverConfiguration::read(solver_file(name)), world);
    const double dt = 1.0 / 24.0;
    system.assemble(std::sqrt(10.0) * dt);  // the larger Δt first: its graph covers both
    const std::uint64_t pattern = system.sim.integrator().newton_system().pattern_version();
    system.assemble(dt);
    system.assemble(std::sqrt(10.0) * dt);
    ASSERT_EQ(system.sim.integrator().newton_system().pattern_version(), pattern) << name << ": the same graph";
    const auto report = system.solve();
    EXPECT_TRUE(report.converged) << name << ": " << report.failure;
    EXPECT_LT(report.relative_residual, 1e-5) << name;
  }
}

TEST(SolverConfigurations, MatrixFreeHessianEqualsTheAssembledOneOnRandomVectors) {
  const parallel::Communicator comm(MPI_COMM_WORLD);
  simulation::Simulation sim(testkit::sponge_scene(), testkit::jacobi_cg(1e-8), comm);
  auto& integrator = sim.integrator();
  integrator.prepare(sim.particles(), 4e-3);
  const auto objective = integrator.build_objective(sim.particles(), 0.0, 4e-3);
  linalg::NewtonSystem assembled(integrator.node_space(),
                                 linalg::SolverConfiguration::read(VISCOMPM_SOURCE_DIR "/inputs/solvers/jacobi_cg.xml"));
  linalg::NewtonSystem matrix_free(
      integrator.node_space(), linalg::SolverConfiguration::read(VISCOMPM_SOURCE_DIR "/inputs/solvers/matrix_free_jacobi_cg.xml"));
  ASSERT_TRUE(matrix_free.matrix_free());
  std::mt19937 rng(7 + comm.rank());
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (bool project : {false, true}) {
    assembled.assemble(*objective->potential, objective->initial_guess, project);
    matrix_free.assemble(*objective->potential, objective->initial_guess, project);
    for (int trial = 0; trial < 3; ++trial) {
      NodeVectorField x(integrator.layout().local_node_count()), y_assembled, y_matrix_free;
      for (auto& xi : x) xi = Vec3(u(rng), u(rng), u(rng));
      integrator.node_space().import_ghosts(x);
      assembled.apply(x, y_assembled);
      matrix_free.apply(x, y_matrix_free);
      double difference = 0.0, norm = 0.0;
      for (std::size_t i = 0; i < integrator.layout().owned_count; ++i) {
        difference = std::max(difference, (y_assembled[i] - y_matrix_free[i]).norm());
        norm = std::max(norm, y_assembled[i].norm());
      }
      EXPECT_LT(comm.max(difference), 1e-12 * comm.max(norm)) << (project ? "projected" : "exact");
    }
  }
}

TEST(SolverConfigurations, AOneRankSolverFileIsBadInputOnMoreRanks) {
  // one_rank/muelu_brick_cg.xml says "Ranks" = 1: on more ranks the Newton system refuses it at
  // set-up, naming the file and the parameter, before anything is solved.
  const parallel::Communicator world(MPI_COMM_WORLD);
  const auto config = linalg::SolverConfiguration::read(solver_file("one_rank/muelu_brick_cg.xml"));
  auto make = [&] { StiffSystem system(config, world); };
  if (world.size() == 1) {
    EXPECT_NO_THROW(make());
  } else {
    try {
      make();
      ADD_FAILURE() << "a one-rank solver file was accepted on " << world.size() << " ranks";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("muelu_brick_cg.xml: parameter 'Ranks'"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("one rank"), std::string::npos) << e.what();
    }
  }
}

TEST(SolverConfigurations, EverySpellingOfBlockRelaxationGivesTheSameSmoother) {
  // Ifpack2 accepts its block relaxation as BLOCK_RELAXATION, BLOCK RELAXATION and BLOCKRELAXATION;
  // the reader parses the word once, so every spelling gets the one-block-per-node partition and
  // the same solve (a spelling compared as a string further down would get Ifpack2's default
  // partition: one block for the whole rank, a direct solve).
  const parallel::Communicator world(MPI_COMM_WORLD);
  auto file = [](const std::string& type) {
    return "<ParameterList name=\"x\"><Parameter name=\"Preconditioner\" type=\"string\" value=\"Ifpack2\"/>"
           "<Parameter name=\"Ifpack2 type\" type=\"string\" value=\"" + type + "\"/>"
           "<ParameterList name=\"Krylov parameters\"><Parameter name=\"Convergence Tolerance\" type=\"double\" "
           "value=\"1e-8\"/><Parameter name=\"Maximum Iterations\" type=\"int\" value=\"2000\"/></ParameterList>"
           "<ParameterList name=\"Preconditioner parameters\"><Parameter name=\"relaxation: type\" type=\"string\" "
           "value=\"Jacobi\"/></ParameterList></ParameterList>";
  };
  std::vector<linalg::LinearSolveReport> reports;
  for (const char* spelling : {"BLOCK_RELAXATION", "BLOCK RELAXATION", "BLOCKRELAXATION"}) {
    const auto config = linalg::SolverConfiguration::from_xml(file(spelling), spelling);
    EXPECT_EQ(config.label(), "Ifpack2 BLOCK_RELAXATION Jacobi") << spelling;
    reports.push_back(solve_sponge_system(config, world));
    EXPECT_TRUE(reports.back().converged) << spelling;
  }
  // Node blocks need more than a handful of iterations on this system; one rank-sized block would not.
  EXPECT_GT(reports[0].iterations, 10);
  for (const auto& r : reports) {
    EXPECT_EQ(r.iterations, reports[0].iterations);
    EXPECT_DOUBLE_EQ(r.relative_residual, reports[0].relative_residual);
  }
}

namespace {
// A shipped solver file with top-level parameters set: each (key, value, type) replaces the
// file's entry or is added.
struct TopLevelParameter {
  std::string key, value, type = "string";
};
linalg::SolverConfiguration with_parameters(const std::string& name, const std::vector<TopLevelParameter>& parameters) {
  std::ifstream in(solver_file(name));
  std::stringstream text;
  text << in.rdbuf();
  std::string xml = text.str();
  std::string origin = name + " with";
  for (const auto& [key, value, type] : parameters) {
    const std::string element = "<Parameter name=\"" + key + "\" type=\"" + type + "\" value=\"" + value + "\"/>";
    if (const std::size_t old = xml.find("<Parameter name=\"" + key + "\""); old != std::string::npos) {
      xml.replace(old, xml.find("/>", old) + 2 - old, element);
    } else {
      const std::size_t body = xml.find('>', xml.find("<ParameterList name=")) + 1;
      xml.insert(body, element);
    }
    origin += " " + key + " = " + value;
  }
  return linalg::SolverConfiguration::from_xml(xml, origin);
}
// The same for one parameter `key` (a string unless `type` says otherwise).
linalg::SolverConfiguration with_parameter(const std::string& name, const std::string& key, const std::string& value,
                                           const std::string& type = "string") {
  return with_parameters(name, {{key, value, type}});
}

// Random owned entries (ghosts imported), and the dot product over owned nodes.
NodeVectorField random_field(simulation::Simulation& sim, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  NodeVectorField x(sim.integrator().layout().local_node_count());
  for (auto& xi : x) xi = Vec3(u(rng), u(rng), u(rng));
  sim.integrator().node_space().import_ghosts(x);
  return x;
}
double dot(simulation::Simulation& sim, const NodeVectorField& a, const NodeVectorField& b,
           const parallel::Communicator& comm) {
  double sum = 0.0;
  for (std::size_t i = 0; i < sim.integrator().layout().owned_count; ++i) sum += a[i].dot(b[i]);
  return comm.sum(sum);
}
}  // namespace

TEST(SolverConfigurations, TheLeanCycleTakesTheIterationsOfMueLusCycle) {
  // Cycle = lean applies the fine level itself (the same grid-line blocks, damped by the same
  // estimate) and MueLu's levels below: the same V-cycle without Ifpack2's containers, so CG must
  // take the same iterations (±5 %) on the stiff inclusions.
  const parallel::Communicator world(MPI_COMM_WORLD);
  StiffSystem muelu(linalg::SolverConfiguration::read(solver_file("gmg_lines_cg.xml")), world);
  StiffSystem lean(with_parameter("gmg_lines_cg.xml", "Cycle", "lean"),
                   world);
  muelu.assemble(1.0 / 24.0);
  lean.assemble(1.0 / 24.0);
  const auto muelu_report = muelu.solve(), lean_report = lean.solve();
  ASSERT_TRUE(muelu_report.converged);
  EXPECT_TRUE(lean_report.converged) << lean_report.failure;
  EXPECT_LT(lean_report.relative_residual, 1e-5);
  EXPECT_NEAR(lean_report.iterations, muelu_report.iterations, 0.05 * muelu_report.iterations + 1);
  if (world.is_root())
    std::cout << "  stiff inclusions: MueLu cycle " << muelu_report.iterations << ", lean cycle "
              << lean_report.iterations << " iterations\n";
}

TEST(SolverConfigurations, TheLeanCycleOnAOneLevelHierarchyIsMueLusCoarseSolver) {
  // A grid no larger than Coarsest nodes is one level, which MueLu solves with its coarse solver
  // (the shaving foam's first steps on 2 ranks): the lean cycle has no level below to wrap, so
  // it is MueLu's one-level preconditioner, and CG takes its iterations exactly.
  const parallel::Communicator world(MPI_COMM_WORLD);
  auto one_level = [](const std::string& cycle) {
    return with_parameters("gmg_lean_deflated_cg.xml", {{"Coarsest nodes", "100000000", "int"}, {"Cycle", cycle}});
  };
  StiffSystem lean(one_level("lean"), world), muelu(one_level("MueLu"), world);
  lean.assemble(1.0 / 24.0);
  muelu.assemble(1.0 / 24.0);
  const auto lean_report = lean.solve(), muelu_report = muelu.solve();
  ASSERT_TRUE(muelu_report.converged) << muelu_report.failure;
  EXPECT_TRUE(lean_report.converged) << lean_report.failure;
  EXPECT_LT(lean_report.relative_residual, 1e-5);
  EXPECT_EQ(lean_report.iterations, muelu_report.iterations);
}

namespace {
// ⟨x, M y⟩ = ⟨M x, y⟩ and ⟨x, M x⟩ > 0 for the system's preconditioner M on three pairs of random
// vectors (seeded by `seed` and the rank).
void expect_spd_preconditioner(StiffSystem& system, const parallel::Communicator& world, int seed, const std::string& label) {
  auto& newton = system.sim.integrator().newton_system();
  std::mt19937 rng(seed + world.rank());
  for (int trial = 0; trial < 3; ++trial) {
    const NodeVectorField x = random_field(system.sim, rng), y = random_field(system.sim, rng);
    NodeVectorField mx, my;
    newton.apply_preconditioner(x, mx);
    newton.apply_preconditioner(y, my);
    const double xmy = dot(system.sim, x, my, world), mxy = dot(system.sim, mx, y, world);
    EXPECT_NEAR(xmy, mxy, 1e-8 * std::sqrt(dot(system.sim, mx, mx, world) * dot(system.sim, y, y, world))) << label;
    EXPECT_GT(dot(system.sim, x, mx, world), 0.0) << label;
  }
}
}  // namespace

TEST(SolverConfigurations, TheDeflatedLeanCycleIsSymmetricPositiveDefinite) {
  // CG needs an SPD preconditioner: ⟨x, M y⟩ = ⟨M x, y⟩ and ⟨x, M x⟩ > 0 on random vectors, for
  // the lean cycle alone and deflated by the stiff bodies' rigid motions (the balancing form is
  // SPD for any SPD M, also for an H changed since Q was built: assembled again at another Δt).
  const parallel::Communicator world(MPI_COMM_WORLD);
  for (const char* deflation : {"none", "stiff bodies"}) {
    StiffSystem system(with_parameter("gmg_lean_deflated_cg.xml", "Deflation", deflation),
                       world);
    system.assemble(1.0 / 24.0);
    expect_spd_preconditioner(system, world, 11, deflation);
  }
}

TEST(SolverConfigurations, MoreFineSweepsKeepTheLeanCycleSpdAndCutItsIterations) {
  // Fine sweeps = k: k grid-line sweeps before and after the coarse correction. The cycle must
  // stay SPD (the post-sweeps mirror the pre-sweeps) and a stronger fine level must take fewer
  // CG iterations: 3 sweeps at most 80 % of 1 sweep's on the stiff inclusions (measured on the
  // resolution systems: 44 → 24 at Δx 0.02, 56 → 32 at 0.01; doc/performance.md).
  const parallel::Communicator world(MPI_COMM_WORLD);
  int iterations[2] = {0, 0};
  for (int k : {1, 3}) {
    StiffSystem system(with_parameter("gmg_lean_deflated_cg.xml", "Fine sweeps", std::to_string(k), "int"), world);
    system.assemble(1.0 / 24.0);
    expect_spd_preconditioner(system, world, 23 + k, "Fine sweeps = " + std::to_string(k));
    const auto report = system.solve();
    EXPECT_TRUE(report.converged) << report.failure;
    EXPECT_LT(report.relative_residual, 1e-5);
    iterations[k == 1 ? 0 : 1] = report.iterations;
  }
  EXPECT_LE(iterations[1], 0.8 * iterations[0]) << "3 sweeps against 1";
  if (world.is_root())
    std::cout << "  stiff inclusions, lean cycle: 1 sweep " << iterations[0] << " iterations, 3 sweeps " << iterations[1] << "\n";
}

TEST(SolverConfigurations, AChebyshevFineSmootherKeepsTheLeanCycleSpdAndBeatsAsManySweeps) {
  // Fine smoother = Chebyshev: the k fine steps are the Chebyshev iteration on the undamped line
  // blocks, at the cost of k damped sweeps. The cycle must stay SPD, and at the same k = 3 take
  // fewer CG iterations than the sweeps (measured on the resolution systems of the stiff
  // inclusions: 24 → 20 at Δx 0.02, 32 → 25 at 0.01; doc/performance.md). The shipped
  // gmg_lean_chebyshev_cg.xml (degree 5) must be SPD and converge as well.
  const parallel::Communicator world(MPI_COMM_WORLD);
  auto with_three = [](const std::string& smoother) {
    return with_parameters("gmg_lean_deflated_cg.xml", {{"Fine sweeps", "3", "int"},
                                                        {"Fine smoother", smoother},
                                                        {"Fine Chebyshev ratio", "30", "double"},
                                                        {"Fine Chebyshev boost", "1.3", "double"}});
  };
  int iterations[2] = {0, 0};
  const char* smoothers[2] = {"sweeps", "Chebyshev"};
  for (int k = 0; k < 2; ++k) {
    StiffSystem system(with_three(smoothers[k]), world);
    system.assemble(1.0 / 24.0);
    expect_spd_preconditioner(system, world, 31 + k, smoothers[k]);
    const auto report = system.solve();
    EXPECT_TRUE(report.converged) << smoothers[k] << ": " << report.failure;
    EXPECT_LT(report.relative_residual, 1e-5);
    iterations[k] = report.iterations;
  }
  EXPECT_LT(iterations[1], iterations[0]) << "Chebyshev against sweeps, 3 steps each";
  StiffSystem shipped(linalg::SolverConfiguration::read(solver_file("gmg_lean_chebyshev_cg.xml")), world);
  shipped.assemble(1.0 / 24.0);
  expect_spd_preconditioner(shipped, world, 37, "gmg_lean_chebyshev_cg.xml");
  const auto report = shipped.solve();
  EXPECT_TRUE(report.converged) << report.failure;
  EXPECT_LT(report.relative_residual, 1e-5);
  EXPECT_LE(report.iterations, iterations[1]) << "degree 5 against degree 3";
  if (world.is_root())
    std::cout << "  stiff inclusions, lean cycle, 3 fine steps: sweeps " << iterations[0] << " iterations, Chebyshev "
              << iterations[1] << "; degree 5 (shipped file) " << report.iterations << "\n";
}

TEST(SolverConfigurations, TheLeanCycleSetsUpOnAnIndefiniteHessian) {
  // Newton's first attempt assembles H without projecting the particle Hessians (adaptive
  // projection), and a crushed and stretched body makes it indefinite: a grid line's block of it
  // may then have no Cholesky factor (the demo's sponge at frame 8 ended in an internal error on
  // one rank). The lean cycle must set up anyway (those lines smoothed by |diag H|) and CG report
  // what it reached, so that Newton can judge the direction and project; projected at the same
  // state, the cycle is SPD and CG converges.
  const parallel::Communicator world(MPI_COMM_WORLD);
  StiffSystem system(with_parameter("gmg_lean_deflated_cg.xml", "Deflation", "none"), world);
  std::mt19937 crush(5);
  std::uniform_real_distribution<double> stretch(0.15, 3.0);
  for (auto& F : system.sim.particles().deformation_gradient)
    F = Mat3(Eigen::Vector3d(stretch(crush), stretch(crush), stretch(crush)).asDiagonal());
  ASSERT_NO_THROW(system.assemble(1.0 / 24.0, /*project=*/false));
  linalg::LinearSolveReport indefinite;
  ASSERT_NO_THROW(indefinite = system.solve());
  EXPECT_FALSE(indefinite.converged && indefinite.relative_residual > indefinite.tolerance) << "claims a convergence it did not reach";

  ASSERT_NO_THROW(system.assemble(1.0 / 24.0, /*project=*/true));
  expect_spd_preconditioner(system, world, 17, "projected");
  const auto projected = system.solve();
  EXPECT_TRUE(projected.converged) << projected.failure;
  EXPECT_LT(projected.relative_residual, 1e-5);
  if (world.is_root())
    std::cout << "  indefinite H: CG " << indefinite.iterations << " iterations, residual " << indefinite.relative_residual
              << (indefinite.converged ? " (converged)" : " (not converged)") << "; projected: " << projected.iterations
              << " iterations\n";
}

TEST(SolverConfigurations, ABrokenDownSolveReportsItsOwnIterationsNotTheLastSolves) {
  // Belos' CG throws when it meets a non-positive p·Ap (an indefinite H assembled unprojected), and
  // its manager then still holds the previous solve's iteration count: solver.csv showed a solve
  // that broke down at once with the iterations of the solve before it, and the measured choice's
  // seconds per iteration and the reuse rules took that count. A breakdown must report the
  // iterations it ran: the same after a long solve as in a system that solved nothing before.
  const parallel::Communicator world(MPI_COMM_WORLD);
  const auto config = linalg::SolverConfiguration::read(solver_file("matrix_free_jacobi_cg.xml"));
  // The same stretches for the same particle whatever the order the particles are held in (the
  // first assembly sorts them into cells): seeded by the particle's id.
  auto crush = [](StiffSystem& system) {
    auto& particles = system.sim.particles();
    std::uniform_real_distribution<double> stretch(0.15, 3.0);
    for (std::size_t p = 0; p < particles.size(); ++p) {
      std::mt19937 crushing(static_cast<std::uint32_t>(5 + 7919 * particles.id[p]));
      particles.deformation_gradient[p] =
          Mat3(Eigen::Vector3d(stretch(crushing), stretch(crushing), stretch(crushing)).asDiagonal());
    }
  };
  StiffSystem after_a_solve(config, world);
  after_a_solve.assemble(1.0 / 24.0);
  const auto long_solve = after_a_solve.solve();
  ASSERT_TRUE(long_solve.converged);
  ASSERT_GT(long_solve.iterations, 20);
  crush(after_a_solve);
  after_a_solve.assemble(1.0 / 24.0, /*project=*/false);
  const auto broken = after_a_solve.solve();
  ASSERT_FALSE(broken.failure.empty()) << "the crushed, unprojected H must break CG down for this test";
  EXPECT_FALSE(broken.converged);

  StiffSystem first(config, world);
  crush(first);
  first.assemble(1.0 / 24.0, /*project=*/false);
  const auto broken_first = first.solve();
  ASSERT_FALSE(broken_first.failure.empty());
  EXPECT_EQ(broken.iterations, broken_first.iterations) << "a breakdown's count must not depend on the solve before it";
  EXPECT_LT(broken.iterations, long_solve.iterations);
  if (world.is_root())
    std::cout << "  SPD solve " << long_solve.iterations << " iterations; breakdown after " << broken.iterations
              << " (" << broken.failure.substr(0, 60) << ")\n";
}

TEST(SolverConfigurations, DeflatingTheStiffBodiesCutsTheIterationsOnAnyRankCount) {
  // The stiff inclusions' rigid motions are H's softest modes and straddle soft gaps no coarse
  // grid function resolves: on one rank (lines uncut) deflating them must cut the lean cycle's CG
  // iterations at least 2×; on any rank count the deflated solve must take the one-rank count
  // (the bodies are found from all ranks' cells; the line blocks are cut at rank boundaries:
  // ≤ 20 % more per doubling) and still fewer iterations than without deflation.
  const parallel::Communicator world(MPI_COMM_WORLD);
  auto solve = [](const linalg::SolverConfiguration& config, const parallel::Communicator& comm) {
    StiffSystem system(config, comm);
    system.assemble(1.0 / 24.0);
    return system.solve();
  };
  const auto deflated_config = linalg::SolverConfiguration::read(solver_file("gmg_lean_deflated_cg.xml"));
  const auto plain_config = with_parameter("gmg_lean_deflated_cg.xml", "Deflation", "none");
  const auto plain = solve(plain_config, world);
  const auto deflated = solve(deflated_config, world);
  ASSERT_TRUE(plain.converged);
  EXPECT_TRUE(deflated.converged) << deflated.failure;
  EXPECT_LT(deflated.relative_residual, 1e-5);
  EXPECT_LT(deflated.iterations, plain.iterations);
  int reference[2] = {plain.iterations, deflated.iterations};  // one rank: plain, deflated
  if (MPI_Comm solo = testkit::solo_communicator(); solo != MPI_COMM_NULL) {
    reference[0] = solve(plain_config, parallel::Communicator(solo)).iterations;
    reference[1] = solve(deflated_config, parallel::Communicator(solo)).iterations;
    MPI_Comm_free(&solo);
  }
  MPI_Bcast(reference, 2, MPI_INT, 0, MPI_COMM_WORLD);
  EXPECT_LE(2 * reference[1], reference[0]) << "one rank: deflated against plain";
  EXPECT_GE(deflated.iterations, 0.9 * reference[1]);
  EXPECT_LE(deflated.iterations, reference[1] * (1.0 + 0.2 * std::log2(world.size())) + 1);
  if (world.is_root())
    std::cout << "  stiff inclusions, lean cycle: " << plain.iterations << " iterations, deflated "
              << deflated.iterations << " (1 rank: " << reference[0] << ", " << reference[1] << ")\n";
}

TEST(SolverConfigurations, TheMeasuredChoiceTriesEveryCandidateAndAgreesWithThem) {
  // The shipped measured choice's candidates, rechecked every 4 to 8 steps, on the default scene
  // for 20 steps: every Newton direction is computed by one candidate (a solve given up at its
  // budget is computed again by the other), each solves a trial step, a
  // second trial comes on schedule, and the particles agree with a run of the paper's solver alone
  // to Newton's tolerance (the choice changes the linear solver, not the step).
  const parallel::Communicator world(MPI_COMM_WORLD);
  const auto shipped = linalg::SolverConfiguration::read(solver_file("measured_choice_cg.xml"));
  ASSERT_TRUE(shipped.is_choice());
  ASSERT_EQ(shipped.candidates().size(), 2u);
  const auto paper_solver = linalg::SolverConfiguration::read(solver_file("matrix_free_jacobi_cg.xml"));
  EXPECT_EQ(shipped.candidates()[1].label(), paper_solver.label());
  const auto choice = linalg::SolverConfiguration::from_xml(
      "<ParameterList name=\"c\"><Parameter name=\"Choose between\" type=\"Array(string)\" value=\"{" +
          solver_file("gmg_lean_deflated_cg.xml") + ", " + solver_file("matrix_free_jacobi_cg.xml") +
          "}\"/><Parameter name=\"Recheck steps\" type=\"int\" value=\"4\"/>"
          "<Parameter name=\"Max recheck steps\" type=\"int\" value=\"8\"/></ParameterList>",
      "choice.xml");
  const auto scene = scene::read_scene(VISCOMPM_SOURCE_DIR "/inputs/scenes/shooting_sponge.xml",
                                       {{"Newton/Tolerance", "1e-8"}, {"Simulation/Max time step", "2e-3"}});
  auto run = [&](const linalg::SolverConfiguration& config) {
    simulation::Simulation sim(scene, config, world);
    simulation::RunSummary summary;
    sim.advance_to(20 * 2e-3, summary);
    EXPECT_EQ(summary.steps, 20);
    if (const auto* state = sim.integrator().solver_choice()) {
      // Every Newton direction by one candidate, plus the solves given up at their budget (the
      // direction then computed again by the other).
      EXPECT_EQ(state->systems()[0] + state->systems()[1], summary.newton_iterations + state->abandoned());
      EXPECT_GE(state->systems()[0], 1);
      EXPECT_GE(state->systems()[1], 1);
      EXPECT_GE(state->trials(), 2) << "a second trial at most 8 steps after the first";
      if (world.is_root())
        std::cout << "  measured choice: " << state->systems()[0] << " and " << state->systems()[1] << " systems, "
                  << state->trials() << " trials, " << state->stopped_early() << " trial steps stopped early\n";
    }
    return testkit::gather_particles(sim.particles(), world.comm());
  };
  const auto chosen = run(choice);
  const auto paper = run(paper_solver);
  if (!world.is_root()) return;
  const double difference = testkit::max_state_difference(chosen, paper);
  EXPECT_LT(difference, 1e-6) << "positions and velocities of the choice's run against the paper solver's";
  std::cout << "  measured choice, 20 steps: largest difference from the paper's solver " << difference << "\n";
}
