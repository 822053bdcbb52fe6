// Material regions: the particles of the named body inside a region (a sphere; a pattern of
// planar cuts) take the region's material and that material's density; no other particle does.
#include <gtest/gtest.h>

#include <cmath>

#include "scenes.hpp"
#include "viscompm/simulation/simulation.hpp"

using namespace viscompm;

TEST(Regions, AssignTheirMaterialToTheParticlesInside) {
  auto scene = testkit::base_scene(Vec3(1.0, 1.0, 1.0), 0.05);
  scene.materials.push_back(testkit::oldroyd_b_material("crust", 0.5, 500.0, 4000.0, 0.0, "paper", 1e30));
  scene.materials.push_back(testkit::oldroyd_b_material("scored", 0.7, 5.0, 10.0, 0.0, "paper", 1.0));
  scene.materials.push_back(testkit::oldroyd_b_material("filling", 0.2, 5.0, 50.0, 0.0, "paper", 0.1));
  auto crust = testkit::box_body("crust", Vec3(0.2, 0.2, 0.2), Vec3(0.8, 0.5, 0.8), Vec3::Zero());
  crust.name = "crust";
  scene.bodies.push_back(crust);
  auto other = testkit::box_body("crust", Vec3(0.2, 0.6, 0.2), Vec3(0.8, 0.8, 0.8), Vec3::Zero());
  other.name = "lid";  // same material, not named by the regions
  scene.bodies.push_back(other);
  scene::RegionSettings ball;
  ball.name = "ball";
  ball.body = "crust";
  ball.material = "filling";
  ball.shape = scene::ShapeKind::sphere;
  ball.center = Vec3(0.5, 0.35, 0.5);
  ball.radius = 0.12;
  scene::RegionSettings cuts;
  cuts.name = "cuts";
  cuts.body = "crust";
  cuts.material = "scored";
  cuts.shape = scene::ShapeKind::cuts;
  cuts.center = Vec3(0.5, 0.35, 0.5);
  cuts.axis = Vec3::UnitY();
  cuts.cut_count = 3;
  cuts.cut_width = 0.03;
  scene.regions = {cuts, ball};  // later regions win where they overlap
  const parallel::Communicator comm(MPI_COMM_SELF);
  simulation::Simulation sim(scene, testkit::jacobi_cg(1e-8), comm);
  const auto& ps = sim.particles();
  std::size_t in_ball = 0, in_cuts = 0;
  for (std::size_t p = 0; p < ps.size(); ++p) {
    const Vec3& x = ps.position[p];
    const bool crust_body = x.y() < 0.55;
    const bool inside_ball = (x - ball.center).norm() <= ball.radius;
    // Distance to the planes through the centre containing y at 0°, 60° and 120°.
    double nearest = 1.0;
    const Vec3 e1 = Vec3::UnitY().unitOrthogonal(), e2 = Vec3::UnitY().cross(e1);
    for (int k = 0; k < 3; ++k) {
      const double a = M_PI * k / 3;
      nearest = std::min(nearest, std::abs((x - cuts.center).dot(std::cos(a) * e1 + std::sin(a) * e2)));
    }
    const bool inside_cuts = nearest <= 0.015;
    int expected = 0;  // crust
    if (crust_body && inside_cuts) expected = 1;
    if (crust_body && inside_ball) expected = 2;
    ASSERT_EQ(ps.material_id[p], expected) << x.transpose();
    const double density[] = {0.5, 0.7, 0.2};
    EXPECT_DOUBLE_EQ(ps.mass[p], density[expected] * ps.volume0[p]);
    in_ball += expected == 2;
    in_cuts += expected == 1;
  }
  // The sphere holds 4/3 π r³ / h³ ≈ 463 lattice sites; the cuts a few hundred.
  EXPECT_NEAR(static_cast<double>(in_ball), 4.0 / 3.0 * M_PI * std::pow(0.12, 3) / std::pow(0.025, 3), 40.0);
  EXPECT_GT(in_cuts, 200u);
}
