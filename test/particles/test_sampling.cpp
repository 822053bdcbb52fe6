// Sampling fills a solid with particles whose volumes add up to the solid's (to the lattice's
// resolution), inside the shape, with unique ids that do not depend on which rank keeps which.
#include <gtest/gtest.h>

#include <cmath>
#include <set>

#include "viscompm/particles/sampling.hpp"

using namespace viscompm;

namespace {
grid::GridGeometry grid_for_sampling() {
  grid::GridGeometry g;
  g.origin = Vec3(-1.0, -1.0, -1.0);
  g.dx = 0.02;
  g.cells = Int3(100, 100, 100);
  return g;
}

double sampled_volume(const particles::ParticleSet& ps) {
  double v = 0.0;
  for (double v0 : ps.volume0) v += v0;
  return v;
}
}  // namespace

TEST(Sampling, VolumesMatchTheShapes) {
  const auto g = grid_for_sampling();
  struct Case {
    Shape shape;
    double volume;
  };
  std::vector<Case> cases;
  Shape sphere;
  sphere.kind = Shape::Kind::sphere;
  sphere.center = Vec3(0.1, -0.05, 0.02);
  sphere.radius = 0.3;
  cases.push_back({sphere, 4.0 / 3.0 * M_PI * std::pow(0.3, 3)});
  Shape cylinder;
  cylinder.kind = Shape::Kind::cylinder;
  cylinder.center = Vec3(0.0, 0.1, 0.0);
  cylinder.axis = Vec3(1, 1, 0).normalized();
  cylinder.radius = 0.2;
  cylinder.length = 0.6;
  cases.push_back({cylinder, M_PI * 0.04 * 0.6});
  Shape box;
  box.lower = Vec3(-0.3, -0.2, -0.1);
  box.upper = Vec3(0.3, 0.4, 0.1);
  cases.push_back({box, 0.6 * 0.6 * 0.2});
  for (const auto& c : cases) {
    particles::BodySampling body;
    body.shape = c.shape;
    body.particles_per_cell = 2;
    body.density = 3.0;
    particles::ParticleSet ps;
    particles::sample_body(body, g, 0, [](const Vec3&) { return true; }, ps);
    EXPECT_NEAR(sampled_volume(ps), c.volume, 0.03 * c.volume) << Shape::kind_name(c.shape.kind);
    for (std::size_t p = 0; p < ps.size(); ++p) {
      EXPECT_TRUE(c.shape.contains(ps.position[p]));
      EXPECT_DOUBLE_EQ(ps.mass[p], 3.0 * ps.volume0[p]);
    }
  }
}

TEST(Sampling, IdsAreUniqueAndIndependentOfWhichRankKeepsAParticle) {
  const auto g = grid_for_sampling();
  particles::BodySampling body;
  body.shape.kind = Shape::Kind::sphere;
  body.shape.radius = 0.25;
  particles::ParticleSet all, left, right;
  particles::sample_body(body, g, 100, [](const Vec3&) { return true; }, all);
  particles::sample_body(body, g, 100, [](const Vec3& x) { return x.x() < 0.0; }, left);
  particles::sample_body(body, g, 100, [](const Vec3& x) { return x.x() >= 0.0; }, right);
  std::map<ParticleId, Vec3> by_id;
  for (std::size_t p = 0; p < all.size(); ++p) EXPECT_TRUE(by_id.emplace(all.id[p], all.position[p]).second);
  EXPECT_EQ(left.size() + right.size(), all.size());
  for (const auto* part : {&left, &right})
    for (std::size_t p = 0; p < part->size(); ++p) EXPECT_EQ(by_id.at(part->id[p]), part->position[p]);
  // The id range a body reserves covers all its ids.
  const auto reserved = particles::lattice_size(body, g);
  for (const auto& [id, x] : by_id) EXPECT_LT(id, 100 + reserved);
}

// A body reaching beyond the grid fills only the grid: the sites outside it were clamped onto
// its faces (a sphere of radius 3 in a 1.5 m grid gave 14 million particles; found by fuzzing),
// and a bounding box of 10^30 m is neither visited site by site nor overflows the ids.
TEST(Sampling, ABodyLargerThanTheGridFillsTheGridOnly) {
  auto g = grid_for_sampling();  // [-1, 1]^3, here with dx 0.1 (20^3 cells: a test of seconds)
  g.dx = 0.1;
  g.cells = Int3(20, 20, 20);
  for (const double radius : {3.0, 1e30}) {
    particles::BodySampling body;
    body.shape.kind = Shape::Kind::sphere;
    body.shape.center = Vec3(0.5, 0.0, 0.0);
    body.shape.radius = radius;
    body.particles_per_cell = 1;
    particles::ParticleSet ps;
    const std::size_t added = particles::sample_body(body, g, 0, [](const Vec3&) { return true; }, ps);
    EXPECT_EQ(added, 20u * 20u * 20u) << radius;  // one particle per cell of the grid
    EXPECT_EQ(particles::lattice_size(body, g), 8000) << radius;
    for (const Vec3& x : ps.position) EXPECT_TRUE((x.array() > -1.0).all() && (x.array() < 1.0).all()) << x.transpose();
    EXPECT_NEAR(sampled_volume(ps), 8.0, 1e-9);
  }
}
