// Rigid motions of colliders as functions of time: a constant translation velocity and angular
// velocity about an axis through a point, or piecewise-linear keyframes of position and
// orientation, active between a start and a stop time (at rest, where they left off, outside).
// A point X of the solid at the start time is at x(t) = R(t) (X − c) + c + d(t) and moves with
// the rigid velocity v(x, t) = v₀(t) + ω(t) × (x − c − d(t)).
#pragma once

#include <limits>
#include <vector>

#include "viscompm/core/types.hpp"

namespace viscompm::boundary {

/// x ↦ R (x − c) + c + d.
struct RigidTransform {
  Mat3 rotation = Mat3::Identity();
  Vec3 center = Vec3::Zero();       ///< c: the rotation centre at the start time
  Vec3 translation = Vec3::Zero();  ///< d

  Vec3 apply(const Vec3& x) const { return rotation * (x - center) + center + translation; }
  Vec3 inverse(const Vec3& x) const { return rotation.transpose() * (x - center - translation) + center; }
};

struct Keyframe {
  double time = 0.0;
  Vec3 position = Vec3::Zero();  ///< translation d at that time [m]
  Vec3 rotation = Vec3::Zero();  ///< rotation vector (axis · angle [rad]) about the centre
};

class RigidMotion {
 public:
  Vec3 velocity = Vec3::Zero();          ///< v₀ (constant motion)
  Vec3 angular_velocity = Vec3::Zero();  ///< ω [rad/s] (constant motion)
  Vec3 center = Vec3::Zero();            ///< c: a point on the rotation axis at the start time
  double start_time = 0.0;
  double stop_time = std::numeric_limits<double>::infinity();
  std::vector<Keyframe> keyframes;       ///< if not empty: the motion (times increasing)

  /// Where the solid is at time t.
  RigidTransform transform_at(double t) const;
  /// The velocity of the solid's material point at position x (world) at time t.
  Vec3 velocity_at(const Vec3& x, double t) const;
  /// Largest speed of a point within `radius` of the rotation centre over all times (for Δt).
  double max_speed(double radius) const;
  /// True if the solid never moves.
  bool is_static() const;

 private:
  // Translation velocity and angular velocity at time t.
  void rates_at(double t, Vec3& v, Vec3& omega) const;
};

/// exp([θ]×): the rotation by the rotation vector θ.
Mat3 rotation_matrix(const Vec3& rotation_vector);

}  // namespace viscompm::boundary
