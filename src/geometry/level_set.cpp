#include "viscompm/geometry/level_set.hpp"

#include <openvdb/openvdb.h>
#include <openvdb/tools/Interpolation.h>
#include <openvdb/tools/MeshToVolume.h>
#include <openvdb/tools/ParticlesToLevelSet.h>
#include <openvdb/tools/VolumeToMesh.h>

#include <mutex>

#include "viscompm/core/error.hpp"
#include "viscompm/core/stop_request.hpp"

namespace viscompm::geometry {

namespace {
void initialize_openvdb() {
  static std::once_flag once;
  std::call_once(once, [] { openvdb::initialize(); });
}

// OpenVDB's long operations ask this whether to go on: a stop request (a signal) ends them, and
// the caller then throws StopRequested.
struct StopInterrupter : openvdb::util::NullInterrupter {
  bool wasInterrupted(int = -1) override { return stop_signal() != 0; }
};

void throw_if_stopped() {
  if (const int signal = stop_signal()) throw StopRequested(signal);
}
}  // namespace

struct LevelSet::Impl {
  openvdb::FloatGrid::Ptr grid;
};

LevelSet::LevelSet(const TriangleMesh& mesh, double voxel_size, int band_voxels)
    : impl_(std::make_unique<Impl>()), voxel_size_(voxel_size), mesh_(mesh) {
  initialize_openvdb();
  std::vector<openvdb::Vec3s> points;
  points.reserve(mesh.vertices.size());
  for (const Vec3& v : mesh.vertices) points.emplace_back(float(v.x()), float(v.y()), float(v.z()));
  std::vector<openvdb::Vec3I> triangles;
  triangles.reserve(mesh.triangles.size());
  for (const auto& t : mesh.triangles) triangles.emplace_back(t[0], t[1], t[2]);
  const auto transform = openvdb::math::Transform::createLinearTransform(voxel_size);
  // Unsigned distances in the band, signs by flood fill from outside (meshToLevelSet, §5.6).
  StopInterrupter interrupter;
  impl_->grid = openvdb::tools::meshToLevelSet<openvdb::FloatGrid>(interrupter, *transform, points, triangles,
                                                                    static_cast<float>(band_voxels));
  throw_if_stopped();
  mesh.bounding_box(lo_, hi_);
}

LevelSet::~LevelSet() = default;

double LevelSet::signed_distance(const Vec3& x) const {
  const openvdb::FloatGrid::ConstAccessor accessor = impl_->grid->getConstAccessor();
  const openvdb::tools::GridSampler<openvdb::FloatGrid::ConstAccessor, openvdb::tools::BoxSampler> sampler(
      accessor, impl_->grid->transform());
  return sampler.wsSample(openvdb::Vec3R(x.x(), x.y(), x.z()));
}

void LevelSet::bounding_box(Vec3& lo, Vec3& hi) const {
  lo = lo_;
  hi = hi_;
}

namespace {
// The particle list ParticlesToLevelSet reads.
struct ParticleList {
  using PosType = openvdb::Vec3R;
  const std::vector<Vec3>& positions;
  double radius;
  std::size_t size() const { return positions.size(); }
  void getPos(std::size_t n, openvdb::Vec3R& x) const { x = openvdb::Vec3R(positions[n].x(), positions[n].y(), positions[n].z()); }
  void getPosRad(std::size_t n, openvdb::Vec3R& x, openvdb::Real& r) const {
    getPos(n, x);
    r = radius;
  }
};
}  // namespace

TriangleMesh particle_surface(const std::vector<Vec3>& positions, double radius, double voxel_size,
                              const std::string& vdb_file) {
  initialize_openvdb();
  auto grid = openvdb::createLevelSet<openvdb::FloatGrid>(voxel_size, 3.0);
  {
    StopInterrupter interrupter;
    openvdb::tools::ParticlesToLevelSet<openvdb::FloatGrid, void, StopInterrupter> raster(*grid, &interrupter);
    raster.setRmin(0.5);
    raster.rasterizeSpheres(ParticleList{positions, radius});
    raster.finalize(true);
  }
  throw_if_stopped();
  grid->setName("surface");
  if (!vdb_file.empty()) {
    try {
      openvdb::io::File file(vdb_file);
      file.write({grid});
      file.close();
    } catch (const openvdb::Exception& e) {
      throw SimulationError("cannot write " + vdb_file + " (" + e.what() + ")");
    }
  }
  std::vector<openvdb::Vec3s> points;
  std::vector<openvdb::Vec3I> triangles;
  std::vector<openvdb::Vec4I> quads;
  openvdb::tools::volumeToMesh(*grid, points, triangles, quads, 0.0);
  TriangleMesh mesh;
  for (const auto& p : points) mesh.vertices.emplace_back(p.x(), p.y(), p.z());
  // OpenVDB's faces wind clockwise seen from outside: reverse them.
  for (const auto& t : triangles) mesh.triangles.push_back({int(t[2]), int(t[1]), int(t[0])});
  for (const auto& q : quads) {
    mesh.triangles.push_back({int(q[3]), int(q[2]), int(q[1])});
    mesh.triangles.push_back({int(q[3]), int(q[1]), int(q[0])});
  }
  return mesh;
}

}  // namespace viscompm::geometry
