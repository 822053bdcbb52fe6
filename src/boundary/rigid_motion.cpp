#include "viscompm/boundary/rigid_motion.hpp"

#include <Eigen/Geometry>
#include <algorithm>

namespace viscompm::boundary {

Mat3 rotation_matrix(const Vec3& rotation_vector) {
  const double angle = rotation_vector.norm();
  if (angle == 0.0) return Mat3::Identity();
  return Eigen::AngleAxisd(angle, rotation_vector / angle).toRotationMatrix();
}

namespace {
// The keyframe interval [k, k+1] containing t (clamped) and the fraction s of it.
std::size_t segment_of(const std::vector<Keyframe>& keys, double t, double& s) {
  if (t <= keys.front().time || keys.size() == 1) {
    s = 0.0;
    return 0;
  }
  if (t >= keys.back().time) {
    s = 1.0;
    return keys.size() - 2;
  }
  const auto it = std::upper_bound(keys.begin(), keys.end(), t, [](double v, const Keyframe& k) { return v < k.time; });
  const std::size_t k = static_cast<std::size_t>(it - keys.begin()) - 1;
  s = (t - keys[k].time) / (keys[k + 1].time - keys[k].time);
  return k;
}

// The rotation from keyframe k's orientation to k+1's, as a rotation vector (world frame).
Vec3 relative_rotation(const Keyframe& a, const Keyframe& b) {
  const Eigen::AngleAxisd relative(rotation_matrix(b.rotation) * rotation_matrix(a.rotation).transpose());
  return relative.angle() * relative.axis();
}
}  // namespace

RigidTransform RigidMotion::transform_at(double t) const {
  RigidTransform T;
  T.center = center;
  if (!keyframes.empty()) {
    // Linear in position; constant angular velocity between orientations (slerp).
    double s = 0.0;
    const std::size_t k = segment_of(keyframes, t, s);
    if (keyframes.size() == 1) {
      T.translation = keyframes[0].position;
      T.rotation = rotation_matrix(keyframes[0].rotation);
      return T;
    }
    const Keyframe &a = keyframes[k], &b = keyframes[k + 1];
    T.translation = (1.0 - s) * a.position + s * b.position;
    T.rotation = rotation_matrix(s * relative_rotation(a, b)) * rotation_matrix(a.rotation);
    return T;
  }
  const double moving = std::clamp(t, start_time, stop_time) - start_time;
  T.translation = moving * velocity;
  T.rotation = rotation_matrix(moving * angular_velocity);
  return T;
}

void RigidMotion::rates_at(double t, Vec3& v, Vec3& omega) const {
  v.setZero();
  omega.setZero();
  if (!keyframes.empty()) {
    if (keyframes.size() < 2 || t < keyframes.front().time || t >= keyframes.back().time) return;
    double s = 0.0;
    const std::size_t k = segment_of(keyframes, t, s);
    const Keyframe &a = keyframes[k], &b = keyframes[k + 1];
    const double duration = b.time - a.time;
    v = (b.position - a.position) / duration;
    omega = relative_rotation(a, b) / duration;
    return;
  }
  if (t >= start_time && t < stop_time) {
    v = velocity;
    omega = angular_velocity;
  }
}

Vec3 RigidMotion::velocity_at(const Vec3& x, double t) const {
  Vec3 v, omega;
  rates_at(t, v, omega);
  const RigidTransform T = transform_at(t);
  return v + omega.cross(x - T.center - T.translation);
}

double RigidMotion::max_speed(double radius) const {
  if (keyframes.empty()) return velocity.norm() + angular_velocity.norm() * radius;
  double speed = 0.0;
  for (std::size_t k = 0; k + 1 < keyframes.size(); ++k) {
    const double duration = keyframes[k + 1].time - keyframes[k].time;
    speed = std::max(speed, ((keyframes[k + 1].position - keyframes[k].position).norm() +
                             relative_rotation(keyframes[k], keyframes[k + 1]).norm() * radius) /
                                duration);
  }
  return speed;
}

bool RigidMotion::is_static() const { return max_speed(1.0) == 0.0; }

}  // namespace viscompm::boundary
