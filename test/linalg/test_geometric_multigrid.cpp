// Geometric multigrid through MueLu: the hierarchy MueLu sets up has exactly the levels of the
// grid hierarchy (its own aggregation would give other sizes), and its coarse operator is the
// Galerkin product Pᵀ A P, checked against a dense product of the fine matrix and the
// prolongation formed independently from the grid hierarchy's rows.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <map>

#include "gather.hpp"
#include "scenes.hpp"
#include "viscompm/parallel/grid_hierarchy.hpp"
#include "viscompm/simulation/simulation.hpp"

using namespace viscompm;

namespace {
const char* gmg_file = VISCOMPM_SOURCE_DIR "/inputs/solvers/gmg_cg.xml";

struct System {
  std::unique_ptr<simulation::Simulation> sim;
  std::unique_ptr<simulation::StepObjective> objective;
  std::unique_ptr<linalg::NewtonSystem> newton;
};

// The sponge's first Newton system on `comm`, preconditioned by the geometric multigrid with
// the coarsest level at most `coarsest` nodes.
System sponge_system(const parallel::Communicator& comm, int coarsest) {
  System s;
  const auto config = linalg::SolverConfiguration::read(gmg_file);
  s.sim = std::make_unique<simulation::Simulation>(testkit::sponge_scene(), config, comm);
  auto& integrator = s.sim->integrator();
  integrator.prepare(s.sim->particles(), 4e-3);
  s.objective = integrator.build_objective(s.sim->particles(), 0.0, 4e-3);
  std::string xml = "<ParameterList name=\"g\"><Parameter name=\"Preconditioner\" type=\"string\" value=\"MueLu\"/>"
                    "<Parameter name=\"Prolongation\" type=\"string\" value=\"trilinear\"/>"
                    "<Parameter name=\"Coarsest nodes\" type=\"int\" value=\"" + std::to_string(coarsest) + "\"/>"
                    "<ParameterList name=\"Preconditioner parameters\">"
                    "<Parameter name=\"smoother: type\" type=\"string\" value=\"CHEBYSHEV\"/>"
                    "<Parameter name=\"coarse: type\" type=\"string\" value=\"CHEBYSHEV\"/>"
                    "</ParameterList></ParameterList>";
  s.newton = std::make_unique<linalg::NewtonSystem>(integrator.node_space(),
                                                    linalg::SolverConfiguration::from_xml(xml, "test"));
  s.newton->assemble(*s.objective->potential, s.objective->initial_guess, true);
  s.newton->precondition();
  return s;
}

// The grid hierarchy of the system's nodes, as the preconditioner builds it.
std::vector<parallel::CoarseLevel> grid_levels(const simulation::Simulation& sim, const parallel::Communicator& comm,
                                               int coarsest) {
  auto& integrator = const_cast<simulation::Simulation&>(sim).integrator();
  const auto& partition = integrator.node_space().partition();
  std::vector<Int3> owned;
  for (std::size_t i = 0; i < partition.owned_count(); ++i)
    owned.push_back(partition.geometry().node_index(partition.nodes()[i]));
  parallel::HierarchySettings settings;
  settings.coarsest_nodes = coarsest;
  return parallel::build_grid_hierarchy(comm, partition.geometry().nodes(), owned,
                                        [&](const Int3& ijk) { return partition.grid_owner(ijk); }, settings);
}
}  // namespace

TEST(GeometricMultigrid, MueLuTakesTheGridLevelsAskedFor) {
  const parallel::Communicator comm(MPI_COMM_WORLD);
  for (int coarsest : {300, 60}) {
    const System s = sponge_system(comm, coarsest);
    const auto levels = grid_levels(*s.sim, comm, coarsest);
    std::vector<std::int64_t> expected = {s.newton->global_rows()};
    for (const auto& c : levels) expected.push_back(3 * c.global_count);
    EXPECT_EQ(s.newton->preconditioner_levels(), expected) << "coarsest " << coarsest;
    EXPECT_GE(expected.size(), 2u);
    EXPECT_LE(expected.back(), 3 * coarsest);
  }
}

namespace {
// Level 1 of the system's hierarchy against the dense Galerkin product Pᵀ A P of its level 0,
// with P formed from the grid hierarchy's rows: the relative difference (Frobenius).
double galerkin_difference(const System& s, const parallel::Communicator& comm, int coarsest) {
  const auto levels = grid_levels(*s.sim, comm, coarsest);
  EXPECT_GE(levels.size(), 1u);
  const auto& c = levels[0];
  // P by system dof ids, gathered: fine dof 3 i_sys + d, coarse dof 3 J_sys + d, weight.
  const auto& partition = s.sim->integrator().node_space().partition();
  std::vector<double> p_local;
  for (std::size_t r = 0; r + 1 < c.row_begin.size(); ++r)
    for (std::size_t k = c.row_begin[r]; k < c.row_begin[r + 1]; ++k)
      p_local.insert(p_local.end(), {double(partition.system_ids()[r]), double(c.system_ids[c.columns[k]]), c.weights[k]});
  const auto p_all = comm.all_gather(p_local);
  // A by system dof ids (the MueLu level 0 matrix) and its level 1 matrix.
  const auto fine = s.newton->preconditioner_level_entries(0);
  const auto coarse = s.newton->preconditioner_level_entries(1);
  const long long n = s.newton->global_rows(), m = 3 * c.global_count;
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(n, n), P = Eigen::MatrixXd::Zero(n, m), Ac = Eigen::MatrixXd::Zero(m, m);
  for (const auto& [i, j, v] : fine) A(i, j) = v;
  for (std::size_t k = 0; k < p_all.size(); k += 3)
    for (int d = 0; d < 3; ++d) P(3 * static_cast<long long>(p_all[k]) + d, 3 * static_cast<long long>(p_all[k + 1]) + d) = p_all[k + 2];
  for (const auto& [i, j, v] : coarse) Ac(i, j) = v;
  const Eigen::MatrixXd galerkin = P.transpose() * A * P;
  EXPECT_GT(galerkin.norm(), 0.0);
  return (galerkin - Ac).norm() / galerkin.norm();
}
}  // namespace

TEST(GeometricMultigrid, CoarseOperatorIsTheGalerkinProduct) {
  const parallel::Communicator comm(MPI_COMM_WORLD);
  const System s = sponge_system(comm, 300);
  EXPECT_LT(galerkin_difference(s, comm, 300), 1e-12);
}

TEST(GeometricMultigrid, AReusedHierarchyHoldsTheGalerkinProductOfTheNewValues) {
  // A second set-up on the same pattern reuses the hierarchy (the Galerkin products' patterns,
  // values refilled): its coarse operator must be the product of the new matrix, not the old one.
  const parallel::Communicator comm(MPI_COMM_WORLD);
  System s = sponge_system(comm, 300);
  const auto before = s.newton->preconditioner_level_entries(1);
  auto& integrator = s.sim->integrator();
  const std::uint64_t pattern = s.newton->pattern_version();
  integrator.prepare(s.sim->particles(), 2e-3);
  s.objective = integrator.build_objective(s.sim->particles(), 0.0, 2e-3);
  s.newton->assemble(*s.objective->potential, s.objective->initial_guess, true);
  s.newton->precondition();
  ASSERT_EQ(s.newton->pattern_version(), pattern) << "the same graph at the smaller Δt";
  const auto after = s.newton->preconditioner_level_entries(1);
  ASSERT_EQ(after.size(), before.size());
  double changed = 0.0;
  for (std::size_t k = 0; k < after.size(); ++k) changed = std::max(changed, std::abs(std::get<2>(after[k]) - std::get<2>(before[k])));
  EXPECT_GT(changed, 0.0) << "the new Δt changes the coarse operator";
  EXPECT_LT(galerkin_difference(s, comm, 300), 1e-12);
}
