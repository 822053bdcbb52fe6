// The Tpetra assembly (FECrsGraph/FECrsMatrix, shared rows exported to their owners, column
// offsets precomputed per cell) against an independent dense sum of the same element matrices
// and masses by global ids, on every rank count it is registered for.
#include <gtest/gtest.h>

#include <map>

#include "scenes.hpp"
#include "viscompm/simulation/simulation.hpp"

using namespace viscompm;

TEST(NewtonSystem, TpetraAssemblyEqualsTheSumOfElementMatricesByGlobalIds) {
  const parallel::Communicator comm(MPI_COMM_WORLD);
  simulation::Simulation sim(testkit::sponge_scene(), testkit::jacobi_cg(1e-10), comm);
  auto& integrator = sim.integrator();
  integrator.build_layout(sim.particles());
  integrator.particles_to_grid(sim.particles());
  const auto objective = integrator.build_objective(sim.particles(), 0.0, 4e-3);
  for (bool project : {false, true}) {
    integrator.newton_system().assemble(*objective->potential, objective->initial_guess, project);
    const auto tpetra = integrator.newton_system().gather_entries();

    // Reference: (global row, global column, value) of every element entry and owned mass.
    const auto& layout = integrator.layout();
    std::vector<double> triplets;
    const int K = layout.nodes_per_cell();
    objective->potential->element_hessians(objective->initial_guess, project,
                                           [&](std::size_t c, const implicit::ElementMatrix& e) {
      const int* nodes = layout.nodes_of_cell(c);
      for (int a = 0; a < 3 * K; ++a)
        for (int b = 0; b < 3 * K; ++b)
          triplets.insert(triplets.end(), {double(3 * layout.nodes[nodes[a / 3]] + a % 3),
                                           double(3 * layout.nodes[nodes[b / 3]] + b % 3), e(a, b)});
    });
    for (std::size_t i = 0; i < layout.owned_count; ++i)
      for (int d = 0; d < 3; ++d)
        triplets.insert(triplets.end(), {double(3 * layout.nodes[i] + d), double(3 * layout.nodes[i] + d),
                                         integrator.grid_mass()[i]});
    const std::vector<double> all = comm.all_gather(triplets);
    std::map<std::pair<long long, long long>, double> reference;
    for (std::size_t k = 0; k < all.size(); k += 3)
      reference[{static_cast<long long>(all[k]), static_cast<long long>(all[k + 1])}] += all[k + 2];

    ASSERT_EQ(tpetra.size(), reference.size()) << "the graph holds exactly the couplings of occupied cells";
    double scale = 0.0, worst = 0.0;
    for (const auto& [row, column, value] : tpetra) {
      const auto it = reference.find({row, column});
      ASSERT_NE(it, reference.end()) << "entry (" << row << ", " << column << ") is not in any element";
      scale = std::max(scale, std::abs(it->second));
      worst = std::max(worst, std::abs(value - it->second));
    }
    EXPECT_LT(worst, 1e-13 * scale) << (project ? "projected" : "exact");
  }
}
