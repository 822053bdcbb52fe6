#include "viscompm/geometry/mesh.hpp"

#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include "viscompm/core/error.hpp"

namespace viscompm::geometry {

void TriangleMesh::append(const TriangleMesh& other) {
  const int shift = static_cast<int>(vertices.size());
  vertices.insert(vertices.end(), other.vertices.begin(), other.vertices.end());
  for (const auto& t : other.triangles) triangles.push_back({t[0] + shift, t[1] + shift, t[2] + shift});
}

void TriangleMesh::bounding_box(Vec3& lo, Vec3& hi) const {
  lo = Vec3::Constant(std::numeric_limits<double>::infinity());
  hi = -lo;
  for (const Vec3& v : vertices) {
    lo = lo.cwiseMin(v);
    hi = hi.cwiseMax(v);
  }
}

TriangleMesh read_mesh(const std::string& file) {
  if (!std::filesystem::is_regular_file(file)) throw InputError(file + ": no such mesh file");
  Assimp::Importer importer;
  const aiScene* scene = importer.ReadFile(file, 0);
  if (scene == nullptr) throw InputError(file + ": cannot read the mesh (" + importer.GetErrorString() + ")");
  // Every vertex as the file has it, before Assimp merges any: a non-finite corner would merge
  // into another (its comparisons are false) and poison every distance of the level set.
  for (unsigned m = 0; m < scene->mNumMeshes; ++m)
    for (unsigned v = 0; v < scene->mMeshes[m]->mNumVertices; ++v) {
      const aiVector3D& x = scene->mMeshes[m]->mVertices[v];
      if (std::isfinite(x.x) && std::isfinite(x.y) && std::isfinite(x.z)) continue;
      std::ostringstream reason;
      reason << file << ": a vertex (" << x.x << " " << x.y << " " << x.z << ") is not finite";
      throw InputError(reason.str());
    }
  // Triangulate polygons and merge the duplicated corners STL files store per triangle.
  scene = importer.ApplyPostProcessing(aiProcess_Triangulate | aiProcess_JoinIdenticalVertices |
                                       aiProcess_FindDegenerates | aiProcess_SortByPType);
  if (scene == nullptr) throw InputError(file + ": cannot read the mesh (" + importer.GetErrorString() + ")");
  TriangleMesh mesh;
  for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
    const aiMesh* part = scene->mMeshes[m];
    const int shift = static_cast<int>(mesh.vertices.size());
    for (unsigned v = 0; v < part->mNumVertices; ++v)
      mesh.vertices.emplace_back(part->mVertices[v].x, part->mVertices[v].y, part->mVertices[v].z);
    for (unsigned f = 0; f < part->mNumFaces; ++f) {
      const aiFace& face = part->mFaces[f];
      if (face.mNumIndices != 3) continue;  // points and lines
      mesh.triangles.push_back({static_cast<int>(face.mIndices[0]) + shift, static_cast<int>(face.mIndices[1]) + shift,
                                static_cast<int>(face.mIndices[2]) + shift});
    }
  }
  if (mesh.triangles.empty()) throw InputError(file + ": the mesh has no triangles");
  // Meshes of several parts (and STL files) may repeat positions across parts: merge exact
  // duplicates so that closedness is judged on the surface, not on the file's layout.
  std::map<std::array<double, 3>, int> unique;
  std::vector<int> remap(mesh.vertices.size());
  std::vector<Vec3> merged;
  for (std::size_t v = 0; v < mesh.vertices.size(); ++v) {
    const std::array<double, 3> key{mesh.vertices[v].x(), mesh.vertices[v].y(), mesh.vertices[v].z()};
    const auto [it, inserted] = unique.emplace(key, static_cast<int>(merged.size()));
    if (inserted) merged.push_back(mesh.vertices[v]);
    remap[v] = it->second;
  }
  mesh.vertices = std::move(merged);
  for (auto& t : mesh.triangles)
    for (int& i : t) i = remap[i];
  return mesh;
}

TriangleMesh transformed(const TriangleMesh& mesh, double scale, const Vec3& offset) {
  TriangleMesh out = mesh;
  for (Vec3& v : out.vertices) v = scale * v + offset;
  return out;
}

bool is_closed(const TriangleMesh& mesh) {
  // Each directed edge must appear once and its reverse once.
  std::map<std::pair<int, int>, int> directed;
  for (const auto& t : mesh.triangles)
    for (int k = 0; k < 3; ++k) {
      const int a = t[k], b = t[(k + 1) % 3];
      if (a == b) return false;
      if (++directed[{a, b}] > 1) return false;
    }
  for (const auto& [edge, count] : directed)
    if (directed.count({edge.second, edge.first}) == 0) return false;
  return !mesh.triangles.empty();
}

double enclosed_volume(const TriangleMesh& mesh) {
  double six_volume = 0.0;
  for (const auto& t : mesh.triangles)
    six_volume += mesh.vertices[t[0]].dot(mesh.vertices[t[1]].cross(mesh.vertices[t[2]]));
  return six_volume / 6.0;
}

namespace {
// Quads (a, b, c, d) counter-clockwise seen from outside → two triangles.
void add_quad(TriangleMesh& m, int a, int b, int c, int d) {
  m.triangles.push_back({a, b, c});
  m.triangles.push_back({a, c, d});
}

TriangleMesh box_mesh(const Vec3& lo, const Vec3& hi) {
  TriangleMesh m;
  for (int k = 0; k < 8; ++k) m.vertices.emplace_back(k & 1 ? hi.x() : lo.x(), k & 2 ? hi.y() : lo.y(), k & 4 ? hi.z() : lo.z());
  add_quad(m, 0, 2, 3, 1);  // z = lo
  add_quad(m, 4, 5, 7, 6);  // z = hi
  add_quad(m, 0, 1, 5, 4);  // y = lo
  add_quad(m, 2, 6, 7, 3);  // y = hi
  add_quad(m, 0, 4, 6, 2);  // x = lo
  add_quad(m, 1, 3, 7, 5);  // x = hi
  return m;
}

// A closed cylinder (or, with length 0, nothing but its discs) around `axis` through `center`.
TriangleMesh cylinder_mesh(const Vec3& center, const Vec3& axis, double radius, double length, int segments) {
  TriangleMesh m;
  const Vec3 e1 = axis.unitOrthogonal(), e2 = axis.cross(e1);
  for (int end = 0; end < 2; ++end)
    for (int k = 0; k < segments; ++k) {
      const double a = 2.0 * M_PI * k / segments;
      m.vertices.push_back(center + (end - 0.5) * length * axis + radius * (std::cos(a) * e1 + std::sin(a) * e2));
    }
  const int bottom = static_cast<int>(m.vertices.size());
  m.vertices.push_back(center - 0.5 * length * axis);
  m.vertices.push_back(center + 0.5 * length * axis);
  for (int k = 0; k < segments; ++k) {
    const int k1 = (k + 1) % segments;
    add_quad(m, k, k1, segments + k1, segments + k);
    m.triangles.push_back({bottom, k1, k});
    m.triangles.push_back({bottom + 1, segments + k, segments + k1});
  }
  return m;
}

TriangleMesh sphere_mesh(const Vec3& center, double radius, int segments) {
  TriangleMesh m;
  const int rings = std::max(segments / 2, 3);
  m.vertices.push_back(center - radius * Vec3::UnitZ());
  for (int r = 1; r < rings; ++r) {
    const double polar = M_PI * r / rings;
    for (int k = 0; k < segments; ++k) {
      const double a = 2.0 * M_PI * k / segments;
      m.vertices.push_back(center + radius * Vec3(std::sin(polar) * std::cos(a), std::sin(polar) * std::sin(a),
                                                  -std::cos(polar)));
    }
  }
  m.vertices.push_back(center + radius * Vec3::UnitZ());
  const int top = static_cast<int>(m.vertices.size()) - 1;
  auto ring = [&](int r, int k) { return 1 + (r - 1) * segments + (k % segments); };
  for (int k = 0; k < segments; ++k) {
    m.triangles.push_back({0, ring(1, k + 1), ring(1, k)});
    for (int r = 1; r + 1 < rings; ++r) add_quad(m, ring(r, k), ring(r, k + 1), ring(r + 1, k + 1), ring(r + 1, k));
    m.triangles.push_back({top, ring(rings - 1, k), ring(rings - 1, k + 1)});
  }
  return m;
}

// The square of the plane through `point` with normal `n` that covers the box [lo, hi].
TriangleMesh plane_patch(const Vec3& point, const Vec3& n, const Vec3& lo, const Vec3& hi) {
  const Vec3 centre = 0.5 * (lo + hi);
  const Vec3 on_plane = centre - (centre - point).dot(n) * n;
  const double half = 0.5 * (hi - lo).norm();
  const Vec3 e1 = n.unitOrthogonal(), e2 = n.cross(e1);
  TriangleMesh m;
  m.vertices = {on_plane - half * e1 - half * e2, on_plane + half * e1 - half * e2, on_plane + half * e1 + half * e2,
                on_plane - half * e1 + half * e2};
  add_quad(m, 0, 1, 2, 3);
  return m;
}
}  // namespace

TriangleMesh triangulate(const Shape& shape, const Vec3& lo, const Vec3& hi, int segments) {
  switch (shape.kind) {
    case Shape::Kind::box: return box_mesh(shape.lower, shape.upper);
    case Shape::Kind::sphere: return sphere_mesh(shape.center, shape.radius, segments);
    case Shape::Kind::cylinder: return cylinder_mesh(shape.center, shape.axis, shape.radius, shape.length, segments);
    case Shape::Kind::half_space: return plane_patch(shape.center, shape.axis, lo, hi);
    case Shape::Kind::cuts: {
      TriangleMesh m;
      const Vec3 e1 = shape.axis.unitOrthogonal(), e2 = shape.axis.cross(e1);
      for (int k = 0; k < shape.cut_count; ++k) {
        const double a = M_PI * k / shape.cut_count;
        m.append(plane_patch(shape.center, std::cos(a) * e1 + std::sin(a) * e2, lo, hi));
      }
      return m;
    }
    case Shape::Kind::mesh: return {};
  }
  return {};
}

void write_obj(const TriangleMesh& mesh, const std::string& file) {
  std::ofstream out(file);
  out.precision(9);
  for (const Vec3& v : mesh.vertices) out << "v " << v.x() << " " << v.y() << " " << v.z() << "\n";
  for (const auto& t : mesh.triangles) out << "f " << t[0] + 1 << " " << t[1] + 1 << " " << t[2] + 1 << "\n";
  if (!out) throw InputError(file + ": cannot write");
}

}  // namespace viscompm::geometry
