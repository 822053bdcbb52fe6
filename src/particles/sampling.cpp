#include "viscompm/particles/sampling.hpp"

#include <Eigen/Geometry>
#include <cmath>

namespace viscompm::particles {

namespace {
// The sites of a body's lattice: origin + (k + 1/2) h for the k whose site lies in the body's
// bounding box and in the grid (sites outside the grid would be clamped onto its faces).
struct Lattice {
  std::int64_t first[3];  // lattice index of the first site (in units of h from the grid origin)
  std::int64_t count[3];  // sites per dimension
  double h;
  std::int64_t size() const { return count[0] * count[1] * count[2]; }
};

Lattice body_lattice(const BodySampling& body, const grid::GridGeometry& grid) {
  Vec3 lo, hi;
  body.shape.bounding_box(lo, hi);
  Lattice l;
  l.h = grid.dx / body.particles_per_cell;
  for (int d = 0; d < 3; ++d) {
    // In doubles first: a bounding box may reach far beyond the grid.
    const double sites = static_cast<double>(grid.cells[d]) * body.particles_per_cell;
    const double a = std::max(0.0, std::ceil((lo[d] - grid.origin[d]) / l.h - 0.5));
    const double b = std::min(sites - 1.0, std::floor((hi[d] - grid.origin[d]) / l.h - 0.5));
    l.first[d] = b >= a ? static_cast<std::int64_t>(a) : 0;
    l.count[d] = b >= a ? static_cast<std::int64_t>(b - a) + 1 : 0;
  }
  return l;
}
}  // namespace

std::int64_t lattice_size(const BodySampling& body, const grid::GridGeometry& grid) {
  return body_lattice(body, grid).size();
}

std::size_t sample_body(const BodySampling& body, const grid::GridGeometry& grid,
                        ParticleId id_offset, const std::function<bool(const Vec3&)>& keep,
                        ParticleSet& particles) {
  const Lattice l = body_lattice(body, grid);
  const double volume = l.h * l.h * l.h;
  Vec3 lo, hi;
  body.shape.bounding_box(lo, hi);
  const Vec3 centre = 0.5 * (lo + hi);
  std::size_t added = 0;
  for (std::int64_t k = 0; k < l.count[2]; ++k)
    for (std::int64_t j = 0; j < l.count[1]; ++j)
      for (std::int64_t i = 0; i < l.count[0]; ++i) {
        const Vec3 x = grid.origin + l.h * Vec3(static_cast<double>(l.first[0] + i) + 0.5,
                                               static_cast<double>(l.first[1] + j) + 0.5,
                                               static_cast<double>(l.first[2] + k) + 0.5);
        if (!body.shape.contains(x) || !keep(x)) continue;
        const ParticleId pid = id_offset + i + l.count[0] * (j + l.count[1] * k);
        const Vec3 v = body.velocity + body.angular_velocity.cross(x - centre);
        particles.add(pid, x, v, body.density * volume, volume, body.material_id);
        if (body.angular_velocity.squaredNorm() > 0.0) {
          // A rigid rotation has velocity gradient [ω]×; APIC carries it in C_p.
          Mat3 omega_cross;
          omega_cross << 0, -body.angular_velocity.z(), body.angular_velocity.y(),
              body.angular_velocity.z(), 0, -body.angular_velocity.x(),
              -body.angular_velocity.y(), body.angular_velocity.x(), 0;
          particles.affine_velocity.back() = omega_cross;
        }
        ++added;
      }
  return added;
}

}  // namespace viscompm::particles
