// Simple solids shared by particle sampling and colliders: their inside test, signed distance
// and outward normal. Negative distance means inside. A mesh solid holds a DistanceField (the
// narrow-band level set geometry/ builds from a triangle mesh with OpenVDB).
#pragma once

#include <memory>
#include <string>

#include "viscompm/core/types.hpp"

namespace viscompm {

/// A signed distance function given by samples (geometry::LevelSet implements it).
class DistanceField {
 public:
  virtual ~DistanceField() = default;
  /// Negative inside; |value| ≤ the true distance (a narrow band clamps far values).
  virtual double signed_distance(const Vec3& x) const = 0;
  virtual void bounding_box(Vec3& lo, Vec3& hi) const = 0;
};

struct Shape {
  enum class Kind { box, sphere, cylinder, half_space, mesh, cuts };
  Kind kind = Kind::box;
  Vec3 lower = Vec3::Zero();       ///< box: lower corner
  Vec3 upper = Vec3::Ones();       ///< box: upper corner
  Vec3 center = Vec3::Zero();      ///< sphere, cylinder: centre; half-space: a point on the plane
  double radius = 1.0;             ///< sphere, cylinder
  Vec3 axis = Vec3::UnitY();       ///< cylinder: unit axis; half-space: unit outward normal
  double length = 1.0;             ///< cylinder: length along the axis
  std::shared_ptr<const DistanceField> field;  ///< mesh: its signed distance, placed in the scene
  int cut_count = 4;               ///< cuts: planes through `center` containing `axis`, k·180°/count apart
  double cut_width = 0.01;         ///< cuts: thickness of each planar cut [m]

  static std::string kind_name(Kind kind);

  /// The shape moved by `offset`.
  Shape translated(const Vec3& offset) const;
  /// Signed distance: negative inside, positive outside (exact for sphere and half-space,
  /// a standard box/cylinder distance otherwise).
  double signed_distance(const Vec3& x) const;
  bool contains(const Vec3& x) const { return signed_distance(x) <= 0.0; }
  /// Outward unit normal of the nearest boundary point (gradient of the signed distance).
  Vec3 normal(const Vec3& x) const;
  /// Axis-aligned bounding box (half-space, cuts: unbounded, not allowed for sampling).
  void bounding_box(Vec3& lo, Vec3& hi) const;
};

}  // namespace viscompm
