// Every solver configuration in inputs/solvers/ solves a small sponge Newton system on 1 and 2
// ranks with the same iteration count (±10 %); the stiff multigrid files solve a stiff-inclusion
// system (contrast 10⁴ at the frame time step) with the same counts on any rank count; a
// multigrid hierarchy refreshed for a ten times stiffer matrix on the same pattern (reusing what it
// kept) is still an SPD preconditioner; and the matrix-free Hessian equals the assembled one on
// random vectors.
#include <gtest/gtest.h>

#include <filesystem>
#include <cmath>
#include <random>

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
  // Assembles H at Δt (graph and objective of that Δt) and sets its preconditioner up.
  void assemble(double dt) {
    auto& integrator = sim.integrator();
    integrator.prepare(sim.particles(), dt);
    objective = integrator.build_objective(sim.particles(), 0.0, dt);
    ASSERT_TRUE(integrator.first_right_hand_side(*objective, rhs));
    integrator.newton_system().assemble(*objective->potential, objective->initial_guess, true);
    integrator.newton_system().precondition();
  }
  linalg::LinearSolveReport solve() {
    NodeVectorField dv;
    return sim.integrator().newton_system().solve(rhs, dv);
  }
  scene::SceneConfig scene;
  simulation::Simulation sim;
  std::unique_ptr<simulation::StepObjective> objective;
  NodeVectorField rhs;
};
}  // namespace

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
