#include "viscompm/io/collider_output.hpp"

#include "viscompm/geometry/level_set.hpp"
#include "viscompm/geometry/mesh.hpp"

namespace viscompm::io {

namespace {
void append(const geometry::TriangleMesh& mesh, const boundary::RigidTransform& T, std::int64_t id, FrameExtras& extras) {
  const auto shift = static_cast<std::int64_t>(extras.collider_vertices.size() / 3);
  for (const Vec3& v : mesh.vertices) {
    const Vec3 x = T.apply(v);
    extras.collider_vertices.insert(extras.collider_vertices.end(), {x.x(), x.y(), x.z()});
  }
  for (const auto& t : mesh.triangles) {
    extras.collider_triangles.insert(extras.collider_triangles.end(), {t[0] + shift, t[1] + shift, t[2] + shift});
    extras.collider_id.push_back(id);
  }
}

geometry::TriangleMesh surface_of(const Shape& shape, const Vec3& lo, const Vec3& hi) {
  if (shape.kind == Shape::Kind::mesh)
    if (const auto* level_set = dynamic_cast<const geometry::LevelSet*>(shape.field.get())) return level_set->mesh();
  return geometry::triangulate(shape, lo, hi);
}
}  // namespace

void add_collider_surfaces(const boundary::Boundary& boundary, double t, const Vec3& lo, const Vec3& hi,
                           FrameExtras& extras) {
  std::int64_t id = 0;
  for (const auto& collider : boundary.colliders()) {
    const boundary::RigidTransform T = collider.transform_at(t);
    // Unbounded shapes are cut to the grid box as seen from the solid's rest frame.
    append(surface_of(collider.shape, T.inverse(lo).cwiseMin(T.inverse(hi)), T.inverse(lo).cwiseMax(T.inverse(hi))),
           T, id++, extras);
  }
  for (const auto& inflow : boundary.inflows()) append(surface_of(inflow.nozzle, lo, hi), {}, id++, extras);
}

}  // namespace viscompm::io
