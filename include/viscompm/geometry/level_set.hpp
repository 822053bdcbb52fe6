// Narrow-band signed distance fields of triangle meshes (OpenVDB meshToLevelSet, the library
// the thesis used for its surfaces, §5.6) and the surfaces of particle clouds. OpenVDB stays in
// level_set.cpp: no header of it leaks out of geometry/.
#pragma once

#include <memory>
#include <string>

#include "viscompm/core/shape.hpp"
#include "viscompm/geometry/mesh.hpp"

namespace viscompm::geometry {

class LevelSet : public DistanceField {
 public:
  /// The signed distance of a closed mesh sampled on voxels of size `voxel_size`, exact within
  /// `band_voxels` voxels of the surface; beyond, ±band (inside/outside by flood fill). A stop
  /// request (core/stop_request.hpp) ends the computation with StopRequested.
  LevelSet(const TriangleMesh& mesh, double voxel_size, int band_voxels = 3);
  ~LevelSet() override;

  /// Trilinear interpolation of the samples.
  double signed_distance(const Vec3& x) const override;
  void bounding_box(Vec3& lo, Vec3& hi) const override;
  double voxel_size() const { return voxel_size_; }
  /// The mesh the field was built from.
  const TriangleMesh& mesh() const { return mesh_; }

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  double voxel_size_;
  TriangleMesh mesh_;
  Vec3 lo_, hi_;
};

/// The surface of a particle cloud: spheres of `radius` rasterised into a level set of voxel
/// `voxel_size` (OpenVDB ParticlesToLevelSet), meshed at its zero crossing (volumeToMesh).
/// With a non-empty `vdb_file`, the level set is also written there (for renderers). A stop
/// request ends the rasterisation with StopRequested (nothing written).
TriangleMesh particle_surface(const std::vector<Vec3>& positions, double radius, double voxel_size,
                              const std::string& vdb_file = "");

}  // namespace viscompm::geometry
