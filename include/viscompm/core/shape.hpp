// Simple solids shared by particle sampling and colliders: their inside test, signed distance
// and outward normal. Negative distance means inside.
#pragma once

#include <string>

#include "viscompm/core/types.hpp"

namespace viscompm {

struct Shape {
  enum class Kind { box, sphere, cylinder, half_space };
  Kind kind = Kind::box;
  Vec3 lower = Vec3::Zero();       ///< box: lower corner
  Vec3 upper = Vec3::Ones();       ///< box: upper corner
  Vec3 center = Vec3::Zero();      ///< sphere, cylinder: centre; half-space: a point on the plane
  double radius = 1.0;             ///< sphere, cylinder
  Vec3 axis = Vec3::UnitY();       ///< cylinder: unit axis; half-space: unit outward normal
  double length = 1.0;             ///< cylinder: length along the axis

  static Kind kind_from_name(const std::string& name);
  static std::string kind_name(Kind kind);

  /// The shape moved by `offset` (kinematic colliders).
  Shape translated(const Vec3& offset) const;
  /// Signed distance: negative inside, positive outside (exact for sphere and half-space,
  /// a standard box/cylinder distance otherwise).
  double signed_distance(const Vec3& x) const;
  bool contains(const Vec3& x) const { return signed_distance(x) <= 0.0; }
  /// Outward unit normal of the nearest boundary point (gradient of the signed distance).
  Vec3 normal(const Vec3& x) const;
  /// Axis-aligned bounding box (half-space: unbounded, not allowed for sampling).
  void bounding_box(Vec3& lo, Vec3& hi) const;
};

}  // namespace viscompm
