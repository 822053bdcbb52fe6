// Meshes and their level sets: OBJ, ASCII STL and binary STL read to the same surface; the
// signed distance of a sphere mesh matches the analytic one within a cell; a body sampled from a
// closed mesh has the mesh's volume; open meshes are told apart; scene errors name the scene
// file, the parameter and the mesh file; a stop request ends OpenVDB's level-set builds.
#include <gtest/gtest.h>

#include <cmath>
#include <csignal>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "viscompm/core/error.hpp"
#include "viscompm/core/stop_request.hpp"
#include "viscompm/geometry/level_set.hpp"
#include "viscompm/geometry/mesh.hpp"
#include "viscompm/particles/sampling.hpp"
#include "viscompm/scene/scene.hpp"

using namespace viscompm;

namespace {
std::string temp_path(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() / "viscompm_geometry";
  std::filesystem::create_directories(dir);
  return (dir / name).string();
}

geometry::TriangleMesh sphere_mesh(const Vec3& centre, double radius, int segments) {
  Shape sphere;
  sphere.kind = Shape::Kind::sphere;
  sphere.center = centre;
  sphere.radius = radius;
  return geometry::triangulate(sphere, Vec3::Zero(), Vec3::Zero(), segments);
}

void write_ascii_stl(const geometry::TriangleMesh& m, const std::string& file) {
  std::ofstream out(file);
  out.precision(10);
  out << "solid test\n";
  for (const auto& t : m.triangles) {
    out << " facet normal 0 0 0\n  outer loop\n";
    for (int k = 0; k < 3; ++k) {
      const Vec3& v = m.vertices[t[k]];
      out << "   vertex " << v.x() << " " << v.y() << " " << v.z() << "\n";
    }
    out << "  endloop\n endfacet\n";
  }
  out << "endsolid test\n";
}

void write_binary_stl(const geometry::TriangleMesh& m, const std::string& file) {
  std::ofstream out(file, std::ios::binary);
  char header[80] = {};
  std::strncpy(header, "binary test mesh", sizeof(header));
  out.write(header, 80);
  const std::uint32_t n = static_cast<std::uint32_t>(m.triangles.size());
  out.write(reinterpret_cast<const char*>(&n), 4);
  for (const auto& t : m.triangles) {
    float values[12] = {0, 0, 0};
    for (int k = 0; k < 3; ++k)
      for (int d = 0; d < 3; ++d) values[3 + 3 * k + d] = static_cast<float>(m.vertices[t[k]][d]);
    out.write(reinterpret_cast<const char*>(values), sizeof(values));
    const std::uint16_t attribute = 0;
    out.write(reinterpret_cast<const char*>(&attribute), 2);
  }
}
}  // namespace

TEST(Mesh, ObjAsciiStlAndBinaryStlReadToTheSameClosedSurface) {
  const auto sphere = sphere_mesh(Vec3(0.1, 0.2, 0.3), 0.25, 24);
  ASSERT_TRUE(geometry::is_closed(sphere));
  geometry::write_obj(sphere, temp_path("sphere.obj"));
  write_ascii_stl(sphere, temp_path("sphere_ascii.stl"));
  write_binary_stl(sphere, temp_path("sphere_binary.stl"));
  const double exact_volume = geometry::enclosed_volume(sphere);
  for (const char* name : {"sphere.obj", "sphere_ascii.stl", "sphere_binary.stl"}) {
    const auto read = geometry::read_mesh(temp_path(name));
    EXPECT_EQ(read.vertices.size(), sphere.vertices.size()) << name;  // STL corners merged again
    EXPECT_EQ(read.triangles.size(), sphere.triangles.size()) << name;
    EXPECT_TRUE(geometry::is_closed(read)) << name;
    EXPECT_NEAR(geometry::enclosed_volume(read), exact_volume, 1e-6 * exact_volume) << name;
  }
}

TEST(Mesh, OpenAndMissingMeshesAreToldApart) {
  auto open = sphere_mesh(Vec3::Zero(), 1.0, 12);
  open.triangles.pop_back();  // a hole
  EXPECT_FALSE(geometry::is_closed(open));
  auto flipped = sphere_mesh(Vec3::Zero(), 1.0, 12);
  std::swap(flipped.triangles[0][1], flipped.triangles[0][2]);  // one triangle inside out
  EXPECT_FALSE(geometry::is_closed(flipped));
  EXPECT_THROW(geometry::read_mesh(temp_path("no_such_mesh.obj")), InputError);
  std::ofstream(temp_path("garbage.stl")) << "this is not a mesh\n";
  EXPECT_THROW(geometry::read_mesh(temp_path("garbage.stl")), InputError);
}

TEST(LevelSet, SignedDistanceOfASphereMeshMatchesTheAnalyticDistanceWithinACell) {
  const Vec3 centre(0.5, 0.45, 0.55);
  const double radius = 0.3, cell = 0.02;
  // A fine tessellation: its chordal error (r (1 − cos(π/64)) ≈ 4e-4) is far below a cell.
  const geometry::LevelSet level_set(sphere_mesh(centre, radius, 128), cell / 4, 3);
  const double band = 3 * cell / 4;
  int checked = 0;
  for (int k = 0; k <= 20; ++k)
    for (int j = 0; j <= 20; ++j)
      for (int i = 0; i <= 20; ++i) {
        const Vec3 x = Vec3(0.1, 0.05, 0.15) + 0.04 * Vec3(i, j, k);
        const double exact = (x - centre).norm() - radius;
        const double sdf = level_set.signed_distance(x);
        // Inside the band: the distance to within a cell; beyond it: the right sign, clamped.
        if (std::abs(exact) < band - cell / 4) {
          EXPECT_NEAR(sdf, exact, cell) << x.transpose();
          ++checked;
        } else if (std::abs(exact) > band + cell / 4) {
          EXPECT_EQ(sdf < 0, exact < 0) << x.transpose();
          EXPECT_LE(std::abs(sdf), std::abs(exact) + cell) << x.transpose();
        }
      }
  EXPECT_GT(checked, 50);
  // A shape built on it: inside test and normals point outward.
  Shape mesh_shape;
  mesh_shape.kind = Shape::Kind::mesh;
  mesh_shape.field = std::make_shared<geometry::LevelSet>(sphere_mesh(centre, radius, 128), cell / 4, 3);
  EXPECT_TRUE(mesh_shape.contains(centre));
  EXPECT_FALSE(mesh_shape.contains(centre + Vec3(0.0, 0.0, 1.1 * radius)));
  const Vec3 surface_point = centre + radius * Vec3(1, 1, 0).normalized();
  EXPECT_GT(mesh_shape.normal(surface_point).dot(Vec3(1, 1, 0).normalized()), 0.99);
}

TEST(LevelSet, ABodySampledFromAClosedMeshHasTheMeshVolume) {
  // The head of the pie scene: not convex (nose, ears, neck).
  const std::string head = VISCOMPM_SOURCE_DIR "/inputs/meshes/head.obj";
  const auto mesh = geometry::read_mesh(head);
  ASSERT_TRUE(geometry::is_closed(mesh));
  const double volume = geometry::enclosed_volume(mesh);
  ASSERT_GT(volume, 0.0);
  grid::GridGeometry grid;
  grid.origin = Vec3(-0.2, -0.1, -0.2);
  grid.dx = 0.008;
  grid.cells = Int3(60, 60, 60);
  particles::BodySampling body;
  body.shape.kind = Shape::Kind::mesh;
  body.shape.field = std::make_shared<geometry::LevelSet>(mesh, grid.dx / 4);
  body.particles_per_cell = 2;
  particles::ParticleSet ps;
  particles::sample_body(body, grid, 0, [](const Vec3&) { return true; }, ps);
  double sampled = 0.0;
  for (double v : ps.volume0) sampled += v;
  EXPECT_NEAR(sampled, volume, 0.03 * volume) << "mesh volume " << volume << ", sampled " << sampled;
}

TEST(SceneMeshes, BadMeshesAreOneLineErrorsNamingSceneParameterAndFile) {
  const auto open = [] {
    auto m = sphere_mesh(Vec3(0.5, 0.5, 0.5), 0.2, 12);
    m.triangles.pop_back();
    return m;
  }();
  geometry::write_obj(open, temp_path("open.obj"));
  const std::string scene_file = temp_path("mesh_scene.xml");
  auto write_scene = [&](const std::string& mesh_file, const std::string& section) {
    std::ofstream(scene_file)
        << "<ParameterList name=\"s\">"
           "<ParameterList name=\"Grid\"><Parameter name=\"Cell size\" type=\"double\" value=\"0.05\"/></ParameterList>"
           "<ParameterList name=\"Solver\"><Parameter name=\"File\" type=\"string\" value=\"" VISCOMPM_SOURCE_DIR "/inputs/solvers/jacobi_cg.xml\"/></ParameterList>"
           "<ParameterList name=\"Materials\"><ParameterList name=\"m\"><Parameter name=\"Model\" type=\"string\" value=\"oldroyd_b\"/></ParameterList></ParameterList>"
           "<ParameterList name=\"Bodies\"><ParameterList name=\"b\"><Parameter name=\"Material\" type=\"string\" value=\"m\"/>"
        << (section == "Bodies" ? "<Parameter name=\"Shape\" type=\"string\" value=\"mesh\"/><Parameter name=\"File\" type=\"string\" value=\"" + mesh_file + "\"/>" : "")
        << "</ParameterList></ParameterList>"
        << (section == "Colliders" ? "<ParameterList name=\"Colliders\"><ParameterList name=\"c\"><Parameter name=\"Shape\" type=\"string\" value=\"mesh\"/><Parameter name=\"File\" type=\"string\" value=\"" + mesh_file + "\"/></ParameterList></ParameterList>" : "")
        << "</ParameterList>";
  };
  auto message = [&] {
    try {
      scene::read_scene(scene_file);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  write_scene("open.obj", "Bodies");
  std::string m = message();
  EXPECT_NE(m.find(scene_file), std::string::npos) << m;
  EXPECT_NE(m.find("'Bodies/b/File'"), std::string::npos) << m;
  EXPECT_NE(m.find("open.obj"), std::string::npos) << m;
  EXPECT_NE(m.find("not closed"), std::string::npos) << m;
  EXPECT_EQ(m.find('\n'), std::string::npos) << m;
  write_scene("missing.stl", "Colliders");
  m = message();
  EXPECT_NE(m.find("'Colliders/c/File'"), std::string::npos) << m;
  EXPECT_NE(m.find("missing.stl"), std::string::npos) << m;
  // An open mesh is a valid collider (a surface), a closed one a valid body.
  write_scene("open.obj", "Colliders");
  EXPECT_EQ(message(), "no error");
  geometry::write_obj(sphere_mesh(Vec3(0.5, 0.5, 0.5), 0.2, 12), temp_path("closed.obj"));
  write_scene("closed.obj", "Bodies");
  EXPECT_EQ(message(), "no error");
}

TEST(ParticleSurface, EnclosesTheParticlesOfABallAndIsWrittenForRenderers) {
  // Particles of a ball of radius 0.2 on a lattice of spacing h, as spheres of radius h.
  const double R = 0.2, h = 0.01;
  std::vector<Vec3> positions;
  for (double x = -R; x <= R; x += h)
    for (double y = -R; y <= R; y += h)
      for (double z = -R; z <= R; z += h)
        if (Vec3(x, y, z).norm() <= R) positions.emplace_back(x, y, z);
  const std::string vdb = temp_path("ball_surface.vdb");
  std::filesystem::remove(vdb);
  const auto surface = geometry::particle_surface(positions, h, h / 2, vdb);
  EXPECT_TRUE(std::filesystem::exists(vdb));
  ASSERT_GT(surface.triangles.size(), 1000u);
  const double volume = geometry::enclosed_volume(surface);  // positive: outward-facing triangles
  EXPECT_GT(volume, 4.0 / 3.0 * M_PI * std::pow(R, 3));
  EXPECT_LT(volume, 4.0 / 3.0 * M_PI * std::pow(R + 1.5 * h, 3));
  // The surface lies one particle radius outside the outermost particles.
  Vec3 lo, hi, particles_lo = Vec3::Constant(1.0), particles_hi = Vec3::Constant(-1.0);
  surface.bounding_box(lo, hi);
  for (const Vec3& x : positions) {
    particles_lo = particles_lo.cwiseMin(x);
    particles_hi = particles_hi.cwiseMax(x);
  }
  for (int d = 0; d < 3; ++d) {
    EXPECT_NEAR(hi[d], particles_hi[d] + h, 0.25 * h);
    EXPECT_NEAR(lo[d], particles_lo[d] - h, 0.25 * h);
  }
}

// A stop request (here SIGUSR1, recorded by the handler) ends a mesh's level-set build and a
// frame's surface with StopRequested naming the signal, and the surface's .vdb is not written;
// once the request is forgotten, the same builds complete.
TEST(StopRequest, EndsLevelSetBuildsWithStopRequested) {
  const auto mesh = sphere_mesh(Vec3::Zero(), 0.3, 64);
  const std::vector<Vec3> positions = {Vec3::Zero(), Vec3(0.01, 0.0, 0.0)};
  const std::string vdb = temp_path("stopped_surface.vdb");
  std::filesystem::remove(vdb);
  install_stop_handlers();
  clear_stop_signal();
  std::raise(SIGUSR1);
  ASSERT_EQ(stop_signal(), SIGUSR1);
  try {
    geometry::LevelSet level_set(mesh, 0.01, 3);
    ADD_FAILURE() << "the level set was built despite the stop request";
  } catch (const StopRequested& e) {
    EXPECT_EQ(e.signal, SIGUSR1);
  }
  EXPECT_THROW(geometry::particle_surface(positions, 0.01, 0.005, vdb), StopRequested);
  EXPECT_FALSE(std::filesystem::exists(vdb));
  clear_stop_signal();
  const geometry::LevelSet level_set(mesh, 0.01, 3);
  EXPECT_LT(level_set.signed_distance(Vec3::Zero()), 0.0);
  EXPECT_FALSE(geometry::particle_surface(positions, 0.01, 0.005, vdb).triangles.empty());
  EXPECT_TRUE(std::filesystem::exists(vdb));
}
