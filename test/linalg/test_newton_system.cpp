// The owner-computes Tpetra assembly (rows built from local arrays, own and ghost particles,
// identity rows for the padding) against an independent reference: every rank sums the elements
// of its own cells only, scattered by grid ids into all rows they touch, plus the node masses;
// the gathered sum must equal the assembled matrix entry by entry on every rank count, and
// every other entry of the padded graph must be zero (or an identity row of a node without mass).
#include <gtest/gtest.h>

#include <map>

#include "scenes.hpp"
#include "viscompm/simulation/simulation.hpp"

using namespace viscompm;

TEST(NewtonSystem, OwnerComputesAssemblyEqualsTheSumOfOwnCellElementsByGridIds) {
  const parallel::Communicator comm(MPI_COMM_WORLD);
  simulation::Simulation sim(testkit::sponge_scene(), testkit::jacobi_cg(1e-10), comm);
  auto& integrator = sim.integrator();
  integrator.prepare(sim.particles(), 4e-3);
  const auto objective = integrator.build_objective(sim.particles(), 0.0, 4e-3);
  const auto& layout = integrator.layout();
  const auto& potential = *objective->potential;
  for (bool project : {false, true}) {
    integrator.newton_system().assemble(potential, objective->initial_guess, project);
    const auto tpetra = integrator.newton_system().gather_entries();

    // Reference: (grid row dof, grid column dof, value) of the elements of own cells, in both
    // triangles, and the mass of every owned node with mass.
    std::vector<double> triplets, masses;
    const int K = layout.nodes_per_cell();
    auto add = [&](NodeId i, NodeId j, const Mat3& B) {
      for (int s = 0; s < 3; ++s)
        for (int t = 0; t < 3; ++t) triplets.insert(triplets.end(), {double(3 * i + s), double(3 * j + t), B(s, t)});
    };
    potential.element_hessians(objective->initial_guess, project, [&](std::size_t c, const implicit::ElementHessian& e) {
      if (c >= layout.own_cell_count) return;
      const int* nodes = layout.nodes_of_cell(c);
      for (int a = 0; a < K; ++a)
        for (int b = a; b < K; ++b) {
          const Mat3 B = potential.constrained_block(e, c, a, b);
          add(layout.nodes[nodes[a]], layout.nodes[nodes[b]], B);
          if (b != a) add(layout.nodes[nodes[b]], layout.nodes[nodes[a]], B.transpose());
        }
    });
    for (std::size_t i = 0; i < layout.owned_count; ++i)
      if (integrator.grid_mass()[i] > 0.0) {
        add(layout.nodes[i], layout.nodes[i], integrator.grid_mass()[i] * Mat3::Identity());
        masses.push_back(integrator.grid_mass()[i]);
      }
    const std::vector<double> all = comm.all_gather(triplets);
    std::map<std::pair<long long, long long>, double> reference;
    for (std::size_t k = 0; k < all.size(); k += 3)
      reference[{static_cast<long long>(all[k]), static_cast<long long>(all[k + 1])}] += all[k + 2];
    const std::vector<double> all_masses = comm.all_gather(masses);
    double mean_mass = 0.0;
    for (double m : all_masses) mean_mass += m / all_masses.size();

    // Every reference entry is in the matrix with its value; the rest of the graph is zero but
    // for the identity rows (scaled by the mean node mass) of nodes without mass.
    std::map<long long, int> row_entries;
    double scale = 0.0, worst = 0.0, worst_padding = 0.0;
    std::size_t found = 0, identity_rows = 0;
    for (const auto& [row, column, value] : tpetra) {
      const auto it = reference.find({row, column});
      if (it != reference.end()) {
        ++found;
        scale = std::max(scale, std::abs(it->second));
        worst = std::max(worst, std::abs(value - it->second));
      } else if (row == column) {
        ++identity_rows;
        worst_padding = std::max(worst_padding, std::abs(value - mean_mass) / mean_mass);
      } else {
        worst_padding = std::max(worst_padding, std::abs(value));
      }
    }
    EXPECT_EQ(found, reference.size()) << "the graph holds every coupling of an occupied cell";
    EXPECT_LT(worst, 1e-13 * scale) << (project ? "projected" : "exact");
    EXPECT_LT(worst_padding, 1e-12) << "padding entries are zero, padding rows identity";
    EXPECT_GT(identity_rows, 0u) << "the partition pads the occupied nodes";
    EXPECT_GT(tpetra.size(), reference.size());
  }
}
