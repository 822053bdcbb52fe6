// Triangle meshes: read from OBJ and STL files (ASCII and binary) with Assimp, checked for
// closedness, measured, and made from the simple shapes for output. Assimp stays in mesh.cpp.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "viscompm/core/shape.hpp"

namespace viscompm::geometry {

struct TriangleMesh {
  std::vector<Vec3> vertices;
  std::vector<std::array<int, 3>> triangles;  ///< counter-clockwise seen from outside

  std::size_t size() const { return triangles.size(); }
  /// Appends `other` (its vertex indices shifted).
  void append(const TriangleMesh& other);
  void bounding_box(Vec3& lo, Vec3& hi) const;
};

/// Reads every mesh of an OBJ or STL file (identical vertices merged) into one triangle mesh.
/// Throws InputError("<file>: <reason>") when the file is missing, unreadable, empty or has a
/// non-finite vertex.
TriangleMesh read_mesh(const std::string& file);

/// x ↦ scale·x + offset applied to every vertex.
TriangleMesh transformed(const TriangleMesh& mesh, double scale, const Vec3& offset);

/// True if every edge is shared by exactly two triangles with opposite orientations (a closed,
/// consistently oriented surface: a solid has an inside).
bool is_closed(const TriangleMesh& mesh);

/// Enclosed volume (divergence theorem; positive for outward-facing triangles of a closed mesh).
double enclosed_volume(const TriangleMesh& mesh);

/// A triangulation of a simple shape's surface for output (half-spaces and cuts: the part inside
/// [lo, hi]; a mesh shape: nothing, its file's triangles are used instead). `segments` sets the
/// resolution of round shapes.
TriangleMesh triangulate(const Shape& shape, const Vec3& lo, const Vec3& hi, int segments = 24);

/// Writes an ASCII OBJ file (scripts and tests).
void write_obj(const TriangleMesh& mesh, const std::string& file);

}  // namespace viscompm::geometry
