// The stiff bodies the deflated solvers use (implicit/stiff_bodies): two stiff blocks in soft
// material, four cells apart, are two bodies, each reaching the nodes of its own particles'
// stencils and none of the other's; joined by a stiff bridge they are one; the elastic-CFL
// threshold decides what is stiff, and the body limit keeps the largest.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <unordered_map>

#include "test_helpers.hpp"
#include "viscompm/grid/bspline.hpp"
#include "viscompm/implicit/stiff_bodies.hpp"
#include "viscompm/materials/oldroyd_b.hpp"
#include "viscompm/transfer/transfer.hpp"

using namespace viscompm;

namespace {
constexpr int soft = 0, stiff = 1;

// A 16 × 8 × 8-cell box of material, 8 particles per cell; cells whose x index is in one of
// `stiff_ranges` ([begin, end) in cells, y and z in [2, 6)) are of the stiff material.
struct Blocks {
  grid::GridGeometry geometry;
  particles::ParticleSet particles;
  grid::GridLayout layout;
  materials::MaterialList materials;
  NodeScalarField mass;
  NodeVectorField v_star;
  boundary::NodeConstraints constraints;
  double dt = 1e-2;

  explicit Blocks(const std::vector<std::pair<int, int>>& stiff_ranges, int block_width = 4) {
    geometry.dx = 0.1;
    geometry.cells = Int3(20, 10, 10);
    materials::OldroydBParameters jelly;
    jelly.shear_modulus = 10.0;  // c Δt/Δx ≈ 0.5
    jelly.lame_lambda = 10.0;
    materials::OldroydBParameters plate = jelly;
    plate.shear_modulus = 1e6;  // c Δt/Δx ≈ 170
    plate.lame_lambda = 1e6;
    materials.push_back(std::make_unique<materials::OldroydB>("jelly", jelly));
    materials.push_back(std::make_unique<materials::OldroydB>("plate", plate));
    int id = 0;
    for (int i = 2; i < 18; ++i)
      for (int j = 2; j < 8; ++j)
        for (int k = 2; k < 8; ++k) {
          int material = soft;
          for (const auto& [begin, end] : stiff_ranges)
            if (i >= begin && i < end && j >= 5 - block_width / 2 && j < 5 + block_width / 2 &&
                k >= 5 - block_width / 2 && k < 5 + block_width / 2)
              material = stiff;
          for (int q = 0; q < 8; ++q) {
            const Vec3 offset(0.25 + 0.5 * (q & 1), 0.25 + 0.5 * ((q >> 1) & 1), 0.25 + 0.5 * ((q >> 2) & 1));
            particles.add(id++, geometry.dx * (Vec3(i, j, k) + offset), Vec3::Zero(), 1e-3, 1e-3, material);
          }
        }
    layout = testkit::serial_layout(particles, geometry, grid::KernelOrder::quadratic);
    NodeVectorField momentum;
    transfer::particles_to_grid(particles, layout, transfer::Scheme::pic_flip, mass, momentum);
    v_star.assign(mass.size(), Vec3::Zero());
    constraints.projection.assign(mass.size(), Mat3::Identity());
    constraints.prescribed.assign(mass.size(), Vec3::Zero());
  }

  implicit::StiffBodies find(double elastic_cfl, int max_bodies = 64) const {
    const implicit::IncrementalPotential potential(particles, layout, materials, mass, v_star, constraints, dt);
    return implicit::find_stiff_bodies(potential, elastic_cfl, max_bodies, parallel::Communicator(MPI_COMM_SELF));
  }

  // The local nodes in the stencils of the stiff particles with x in [x0, x1) and y, z in the
  // middle fifth of the box (one cell from the blocks' faces).
  std::set<int> stencil_nodes(double x0, double x1) const {
    std::set<int> nodes;
    std::unordered_map<NodeId, int> local;
    for (std::size_t n = 0; n < layout.nodes.size(); ++n) local.emplace(layout.nodes[n], static_cast<int>(n));
    for (std::size_t p = 0; p < particles.size(); ++p) {
      const Vec3& x = particles.position[p];
      if (particles.material_id[p] != stiff || x.x() < x0 || x.x() >= x1) continue;
      if (std::abs(x.y() - 0.5) > 0.1 || std::abs(x.z() - 0.5) > 0.1) continue;
      const Int3 base = grid::stencil_base(layout.order, (x - geometry.origin) / geometry.dx);
      for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b)
          for (int c = 0; c < 3; ++c) nodes.insert(local.at(geometry.node_id(base + Int3(a, b, c))));
    }
    return nodes;
  }
};

std::set<int> nodes_of_body(const implicit::StiffBodies& bodies, int body) {
  std::set<int> nodes;
  for (const auto& [node, b] : bodies.node_bodies)
    if (b == body) nodes.insert(node);
  return nodes;
}
}  // namespace

TEST(StiffBodies, TwoStiffBlocksInJellyAreTwoBodiesOnTheirOwnNodes) {
  const Blocks scene({{3, 7}, {11, 15}});  // four cells of jelly between them
  const auto bodies = scene.find(30.0);
  ASSERT_EQ(bodies.count, 2);
  ASSERT_EQ(bodies.centroids.size(), 2u);
  // Which body is which: by centroid.
  const int left = bodies.centroids[0].x() < bodies.centroids[1].x() ? 0 : 1;
  EXPECT_NEAR(bodies.centroids[left].x(), 0.5, 1.5 * scene.geometry.dx);
  EXPECT_NEAR(bodies.centroids[1 - left].x(), 1.3, 1.5 * scene.geometry.dx);
  const auto left_nodes = nodes_of_body(bodies, left), right_nodes = nodes_of_body(bodies, 1 - left);
  // Every node of a stiff particle's stencil away from the block's faces belongs to its body ...
  for (const int n : scene.stencil_nodes(0.45, 0.55)) EXPECT_TRUE(left_nodes.count(n)) << "node " << n;
  for (const int n : scene.stencil_nodes(1.25, 1.35)) EXPECT_TRUE(right_nodes.count(n)) << "node " << n;
  // ... and no node belongs to both: the soft gap separates them.
  for (const int n : left_nodes) EXPECT_FALSE(right_nodes.count(n)) << "node " << n << " in both bodies";
  // Nodes reached only by the jelly between the blocks belong to neither.
  const auto& g = scene.geometry;
  std::unordered_map<NodeId, int> local;
  for (std::size_t n = 0; n < scene.layout.nodes.size(); ++n) local.emplace(scene.layout.nodes[n], static_cast<int>(n));
  const int middle = local.at(g.node_id(Int3(9, 5, 5)));
  EXPECT_FALSE(left_nodes.count(middle) || right_nodes.count(middle));
}

TEST(StiffBodies, AStiffBridgeJoinsTheBlocksIntoOneBody) {
  const Blocks scene({{3, 7}, {7, 11}, {11, 15}});
  EXPECT_EQ(scene.find(30.0).count, 1);
}

TEST(StiffBodies, TheElasticCflDecidesWhatIsStiffAndTheLimitKeepsTheLargest) {
  // The plate's c Δt/Δx: above it nothing is stiff, below the jelly's everything is one body.
  const Blocks scene({{3, 5}, {11, 15}});  // the left block half as long as the right one
  const double plate_cfl = scene.materials[stiff]->wave_speed() * scene.dt / scene.geometry.dx;
  const double jelly_cfl = scene.materials[soft]->wave_speed() * scene.dt / scene.geometry.dx;
  ASSERT_GT(plate_cfl, 30.0);
  ASSERT_LT(jelly_cfl, 1.0);
  EXPECT_EQ(scene.find(1.01 * plate_cfl).count, 0);
  EXPECT_EQ(scene.find(0.99 * plate_cfl).count, 2);
  EXPECT_EQ(scene.find(0.99 * jelly_cfl).count, 1);
  const auto largest = scene.find(30.0, 1);
  ASSERT_EQ(largest.count, 1);
  EXPECT_GT(largest.centroids[0].x(), 1.0) << "the right block is the larger";
}
