#include "viscompm/boundary/colliders.hpp"

#include <algorithm>
#include <cmath>

#include "viscompm/core/error.hpp"

namespace viscompm::boundary {

double Collider::signed_distance(const Vec3& x, double t) const {
  return shape.signed_distance(transform_at(t).inverse(x));
}

Vec3 Collider::normal(const Vec3& x, double t) const {
  const RigidTransform T = transform_at(t);
  return T.rotation * shape.normal(T.inverse(x));
}

Vec3 Collider::velocity_at(const Vec3& x, double t) const {
  Vec3 u = motion.velocity_at(x, t);
  if (surface_velocity.squaredNorm() > 0.0) {
    const Vec3 n = normal(x, t);
    const Vec3 s = transform_at(t).rotation * surface_velocity;
    u += s - s.dot(n) * n;
  }
  return u;
}

double Collider::max_speed() const {
  Vec3 lo, hi;
  shape.bounding_box(lo, hi);
  // Unbounded solids (half-spaces) only translate usefully; their rotation speed is not bounded.
  const double reach = lo.allFinite() && hi.allFinite()
                           ? std::max((lo - motion.center).cwiseAbs().maxCoeff(), (hi - motion.center).cwiseAbs().maxCoeff()) *
                                 std::sqrt(3.0)
                           : 0.0;
  return motion.max_speed(reach) + surface_velocity.norm();
}

void NodeConstraints::apply(NodeVectorField& v) const {
  for (std::size_t i = 0; i < v.size(); ++i) v[i] = projection[i] * v[i] + prescribed[i];
}

void NodeConstraints::project(NodeVectorField& dv) const {
  for (std::size_t i = 0; i < dv.size(); ++i) dv[i] = projection[i] * dv[i];
}

namespace {
// Constraints collected at one node: sticky velocity, or normals with their solid velocities.
struct Contacts {
  bool sticky = false;
  Vec3 sticky_velocity = Vec3::Zero();
  std::vector<std::pair<Vec3, Vec3>> normals;  // (unit normal, solid velocity)

  void add(ContactType type, const Vec3& n, const Vec3& u, const Vec3& v_trial) {
    if (type == ContactType::sticky) {
      if (!sticky) sticky_velocity = u;
      sticky = true;
    } else if (type == ContactType::slip || (v_trial - u).dot(n) < 0.0) {
      normals.emplace_back(n, u);
    }
  }
  // P and (I − P) u with the normals made orthonormal (Gram–Schmidt).
  void finish(Mat3& P, Vec3& prescribed) const {
    if (sticky) {
      P.setZero();
      prescribed = sticky_velocity;
      return;
    }
    P.setIdentity();
    prescribed.setZero();
    std::vector<Vec3> basis;
    for (const auto& [n, u] : normals) {
      Vec3 e = n;
      for (const Vec3& b : basis) e -= e.dot(b) * b;
      if (e.norm() < 1e-8) continue;
      e.normalize();
      basis.push_back(e);
      P -= e * e.transpose();
      prescribed += e * e.dot(u);
    }
  }
};
}  // namespace

NodeConstraints Boundary::constrain(const grid::GridLayout& layout, double t,
                                    const NodeVectorField& v_trial) const {
  const std::size_t n = layout.local_node_count();
  NodeConstraints c;
  c.projection.assign(n, Mat3::Identity());
  c.prescribed.assign(n, Vec3::Zero());
  std::vector<RigidTransform> transforms;
  for (const auto& col : colliders_) transforms.push_back(col.transform_at(t));
  const Int3 cells = layout.geometry.cells;
  // Nodes on a solid's surface count as inside (node positions carry rounding).
  const double surface_tolerance = 1e-9 * layout.geometry.dx;
  for (std::size_t i = 0; i < n; ++i) {
    const Int3 ijk = layout.geometry.node_index(layout.nodes[i]);
    const Vec3 x = layout.geometry.node_position(ijk);
    Contacts contacts;
    for (int d = 0; d < 3; ++d) {
      Vec3 inward = Vec3::Zero();
      if (ijk[d] < walls_.thickness) inward[d] = 1.0;
      else if (ijk[d] > cells[d] - walls_.thickness) inward[d] = -1.0;
      if (inward[d] != 0.0) contacts.add(walls_.type, inward, Vec3::Zero(), v_trial[i]);
    }
    for (std::size_t k = 0; k < colliders_.size(); ++k) {
      const Vec3 x_rest = transforms[k].inverse(x);
      if (colliders_[k].shape.signed_distance(x_rest) > surface_tolerance) continue;
      // The solid pushes outward: its outward normal is the contact normal; u = v₀ + ω × (x − c).
      contacts.add(colliders_[k].type, transforms[k].rotation * colliders_[k].shape.normal(x_rest),
                   colliders_[k].velocity_at(x, t), v_trial[i]);
    }
    // Emitters: the nozzle's nodes move with the inflow velocity.
    for (const Inflow& inflow : inflows_)
      if (inflow.active(t) && inflow.nozzle.signed_distance(x) <= surface_tolerance)
        contacts.add(ContactType::sticky, Vec3::UnitY(), inflow.velocity, v_trial[i]);
    if (!contacts.sticky && contacts.normals.empty()) continue;
    contacts.finish(c.projection[i], c.prescribed[i]);
    ++c.constrained_count;
  }
  return c;
}

std::size_t Boundary::delete_outside_particles(const grid::GridGeometry& geometry,
                                              particles::ParticleSet& particles) const {
  const Vec3 lo = geometry.origin + Vec3::Constant(geometry.dx);
  const Vec3 hi = geometry.upper_corner() - Vec3::Constant(geometry.dx * (1.0 + 1e-6));
  std::vector<std::size_t> keep;
  keep.reserve(particles.size());
  for (std::size_t p = 0; p < particles.size(); ++p) {
    const Vec3& x = particles.position[p];
    if ((x.array() >= lo.array()).all() && (x.array() <= hi.array()).all()) keep.push_back(p);
  }
  const std::size_t removed = particles.size() - keep.size();
  if (removed > 0) particles.permute(keep);
  return removed;
}

std::size_t Boundary::clamp_particles(const grid::GridGeometry& geometry,
                                      std::vector<Vec3>& positions) const {
  std::size_t moved = 0;
  const Vec3 lo = geometry.origin + Vec3::Constant(geometry.dx);
  const Vec3 hi = geometry.upper_corner() - Vec3::Constant(geometry.dx * (1.0 + 1e-6));
  for (Vec3& x : positions) {
    const Vec3 clamped = x.cwiseMax(lo).cwiseMin(hi);
    if (clamped != x) {
      x = clamped;
      ++moved;
    }
  }
  return moved;
}

}  // namespace viscompm::boundary
