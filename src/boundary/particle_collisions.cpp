// Particle-based collisions, the last step of §5.5.1 before advection.
#include <cmath>

#include "viscompm/boundary/colliders.hpp"

namespace viscompm::boundary {

namespace {
// Sphere tracing of the segment a → b against a signed distance that never exceeds the true
// distance: steps of the current distance cannot jump over the surface, however thin the solid.
// Returns true with the first point within `tolerance` of the solid (or inside it).
bool first_contact(const Shape& shape, const Vec3& a, const Vec3& b, double tolerance, Vec3& contact) {
  const Vec3 d = b - a;
  const double length = d.norm();
  double s = 0.0;  // distance travelled along the segment
  for (int iteration = 0; iteration < 200; ++iteration) {
    const Vec3 x = length > 0.0 ? Vec3(a + (s / length) * d) : a;
    const double phi = shape.signed_distance(x);
    if (phi <= tolerance) {
      contact = x;
      return true;
    }
    if (s >= length) return false;
    s = std::min(length, s + phi);
  }
  contact = b;
  return shape.signed_distance(b) <= tolerance;
}
}  // namespace

std::size_t Boundary::collide_particles(const std::vector<Vec3>& positions, std::vector<Vec3>& velocities, double t,
                                        double dt) const {
  if (colliders_.empty()) return 0;
  std::vector<RigidTransform> now, next;
  for (const auto& c : colliders_) {
    now.push_back(c.transform_at(t));
    next.push_back(c.transform_at(t + dt));
  }
  std::size_t changed = 0;
  for (std::size_t p = 0; p < positions.size(); ++p) {
    Vec3& v = velocities[p];
    bool hit_any = false;
    for (std::size_t k = 0; k < colliders_.size(); ++k) {
      const Collider& collider = colliders_[k];
      // The path relative to the solid, in its rest frame: where the particle is now, and where
      // it would be at t + Δt, seen from the solid at those times.
      const Vec3 a = now[k].inverse(positions[p]);
      const Vec3 b = next[k].inverse(positions[p] + dt * v);
      const double tolerance = 1e-9 * (1.0 + (b - a).norm());
      Vec3 contact;
      if (!first_contact(collider.shape, a, b, tolerance, contact)) continue;
      const Vec3 x = now[k].apply(contact);
      const Vec3 n = now[k].rotation * collider.shape.normal(contact);
      const Vec3 u = collider.velocity_at(x, t);
      const Vec3 relative = v - u;
      const double approach = relative.dot(n);
      if (collider.type == ContactType::sticky) {
        v = u;
      } else if (approach < 0.0) {
        v = u + relative - approach * n;  // slip, separating: no velocity into the solid
      } else {
        continue;
      }
      hit_any = true;
    }
    changed += hit_any ? 1 : 0;
  }
  return changed;
}

}  // namespace viscompm::boundary
