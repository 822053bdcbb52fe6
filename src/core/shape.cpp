#include "viscompm/core/shape.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "viscompm/core/error.hpp"

namespace viscompm {

std::string Shape::kind_name(Kind kind) {
  switch (kind) {
    case Kind::box: return "box";
    case Kind::sphere: return "sphere";
    case Kind::cylinder: return "cylinder";
    case Kind::half_space: return "half_space";
    case Kind::mesh: return "mesh";
    case Kind::cuts: return "cuts";
  }
  return "?";
}

Shape Shape::translated(const Vec3& offset) const {
  Shape s = *this;
  s.lower += offset;
  s.upper += offset;
  s.center += offset;
  if (kind == Kind::mesh && offset != Vec3::Zero()) {
    // A translated view of the same field.
    struct Translated : DistanceField {
      std::shared_ptr<const DistanceField> base;
      Vec3 offset;
      double signed_distance(const Vec3& x) const override { return base->signed_distance(x - offset); }
      void bounding_box(Vec3& lo, Vec3& hi) const override {
        base->bounding_box(lo, hi);
        lo += offset;
        hi += offset;
      }
    };
    auto moved = std::make_shared<Translated>();
    moved->base = field;
    moved->offset = offset;
    s.field = moved;
  }
  return s;
}

double Shape::signed_distance(const Vec3& x) const {
  switch (kind) {
    case Kind::box: {
      const Vec3 c = 0.5 * (lower + upper), h = 0.5 * (upper - lower);
      const Vec3 q = (x - c).cwiseAbs() - h;
      return q.cwiseMax(0.0).norm() + std::min(q.maxCoeff(), 0.0);
    }
    case Kind::sphere: return (x - center).norm() - radius;
    case Kind::cylinder: {
      const Vec3 r = x - center;
      const double along = r.dot(axis);
      const double across = (r - along * axis).norm();
      const double qa = across - radius, qb = std::abs(along) - 0.5 * length;
      return std::hypot(std::max(qa, 0.0), std::max(qb, 0.0)) + std::min(std::max(qa, qb), 0.0);
    }
    case Kind::half_space: return (x - center).dot(axis);
    case Kind::mesh: return field ? field->signed_distance(x) : std::numeric_limits<double>::infinity();
    case Kind::cuts: {
      // Planes through the centre containing the axis, at angles k·π/count from a fixed normal.
      const Vec3 r = x - center;
      const Vec3 e1 = axis.unitOrthogonal(), e2 = axis.cross(e1);
      double nearest = std::numeric_limits<double>::infinity();
      for (int k = 0; k < cut_count; ++k) {
        const double angle = M_PI * k / cut_count;
        const Vec3 n = std::cos(angle) * e1 + std::sin(angle) * e2;
        nearest = std::min(nearest, std::abs(r.dot(n)));
      }
      return nearest - 0.5 * cut_width;
    }
  }
  return std::numeric_limits<double>::infinity();
}

Vec3 Shape::normal(const Vec3& x) const {
  if (kind == Kind::half_space) return axis;
  if (kind == Kind::sphere) {
    const Vec3 r = x - center;
    const double n = r.norm();
    return n > 0.0 ? Vec3(r / n) : Vec3::UnitY();
  }
  // Central differences of the signed distance, scaled to the shape size (a mesh field: to its
  // sampling, about a tenth of a voxel).
  Vec3 lo, hi;
  bounding_box(lo, hi);
  const double h = kind == Kind::mesh ? 1e-3 * std::max((hi - lo).maxCoeff(), 1e-12)
                   : kind == Kind::cuts ? 1e-6 * cut_width
                                        : 1e-6 * std::max((hi - lo).maxCoeff(), 1e-12);
  Vec3 g;
  for (int d = 0; d < 3; ++d) {
    Vec3 e = Vec3::Zero();
    e[d] = h;
    g[d] = signed_distance(x + e) - signed_distance(x - e);
  }
  const double n = g.norm();
  return n > 0.0 ? Vec3(g / n) : Vec3::UnitY();
}

void Shape::bounding_box(Vec3& lo, Vec3& hi) const {
  switch (kind) {
    case Kind::box: lo = lower; hi = upper; return;
    case Kind::sphere: lo = center.array() - radius; hi = center.array() + radius; return;
    case Kind::cylinder: {
      // Extent of a disc of radius r with normal a along dimension d: r sqrt(1 - a_d^2).
      const Vec3 disc = radius * (Vec3::Ones() - axis.cwiseProduct(axis)).cwiseMax(0.0).cwiseSqrt();
      const Vec3 half = 0.5 * length * axis.cwiseAbs() + disc;
      lo = center - half;
      hi = center + half;
      return;
    }
    case Kind::mesh:
      if (field) {
        field->bounding_box(lo, hi);
        return;
      }
      [[fallthrough]];
    case Kind::cuts:
    case Kind::half_space: {
      const double inf = std::numeric_limits<double>::infinity();
      lo = Vec3::Constant(-inf);
      hi = Vec3::Constant(inf);
      return;
    }
  }
}

}  // namespace viscompm
