#include "viscompm/particles/sampling.hpp"

#include <Eigen/Geometry>
#include <cmath>

namespace viscompm::particles {

namespace {
struct Lattice {
  Int3 first;   // lattice index of the first site (in units of h from the grid origin)
  Int3 count;   // sites per dimension
  double h;
};

Lattice body_lattice(const BodySampling& body, const grid::GridGeometry& grid) {
  Vec3 lo, hi;
  body.shape.bounding_box(lo, hi);
  Lattice l;
  l.h = grid.dx / body.particles_per_cell;
  for (int d = 0; d < 3; ++d) {
    // Sites sit at origin + (k + 1/2) h; keep those whose coordinate lies in [lo, hi].
    const double a = std::ceil((lo[d] - grid.origin[d]) / l.h - 0.5);
    const double b = std::floor((hi[d] - grid.origin[d]) / l.h - 0.5);
    l.first[d] = static_cast<int>(a);
    l.count[d] = std::max(0, static_cast<int>(b - a) + 1);
  }
  return l;
}
}  // namespace

std::int64_t lattice_size(const BodySampling& body, const grid::GridGeometry& grid) {
  const Lattice l = body_lattice(body, grid);
  return static_cast<std::int64_t>(l.count.x()) * l.count.y() * l.count.z();
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
  for (int k = 0; k < l.count.z(); ++k)
    for (int j = 0; j < l.count.y(); ++j)
      for (int i = 0; i < l.count.x(); ++i) {
        const Vec3 x = grid.origin + l.h * ((l.first + Int3(i, j, k)).cast<double>().array() + 0.5).matrix();
        if (!body.shape.contains(x) || !keep(x)) continue;
        const ParticleId pid =
            id_offset + i + static_cast<std::int64_t>(l.count.x()) * (j + static_cast<std::int64_t>(l.count.y()) * k);
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
