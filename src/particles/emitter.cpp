#include "viscompm/particles/emitter.hpp"

#include <cmath>

#include "viscompm/core/error.hpp"

namespace viscompm::particles {

std::vector<Vec3> nozzle_sites(const Shape& nozzle, const Vec3& direction, double h) {
  Vec3 lo, hi;
  nozzle.bounding_box(lo, hi);
  const Vec3 centre = 0.5 * (lo + hi);
  const Vec3 n = direction.normalized();
  const Vec3 e1 = n.unitOrthogonal(), e2 = n.cross(e1);
  const int reach = static_cast<int>(std::ceil(0.5 * (hi - lo).norm() / h));
  std::vector<Vec3> sites;
  for (int j = -reach; j < reach; ++j)
    for (int i = -reach; i < reach; ++i) {
      const Vec3 x = centre + (i + 0.5) * h * e1 + (j + 0.5) * h * e2;
      if (nozzle.contains(x)) sites.push_back(x);
    }
  return sites;
}

Emitter::Emitter(const EmitterSpec& spec, const grid::GridGeometry& grid, ParticleId id_base, ParticleId id_stride,
                 ParticleId id_offset)
    : spec_(spec), id_base_(id_base), id_stride_(id_stride), id_offset_(id_offset) {
  const double h = grid.dx / spec.particles_per_cell;
  sites_ = nozzle_sites(spec.nozzle, spec.velocity, h);
  particle_volume_ = h * h * h;
  particle_mass_ = spec.density * particle_volume_;
  const double layer_mass = particle_mass_ * static_cast<double>(sites_.size());
  // A continuous stream: one layer per h of travel.
  const double rate = spec.mass_rate > 0.0 ? spec.mass_rate : layer_mass * spec.velocity.norm() / h;
  layer_interval_ = sites_.empty() ? std::numeric_limits<double>::infinity() : layer_mass / rate;
}

std::size_t Emitter::emit(double t, const std::function<bool(const Vec3&)>& keep, ParticleSet& particles) {
  std::size_t added = 0;
  for (;;) {
    const double t_k = spec_.start_time + static_cast<double>(layers_) * layer_interval_;
    if (!(t_k <= t) || t_k >= spec_.stop_time) break;
    const Vec3 offset = (t - t_k) * spec_.velocity;
    for (std::size_t j = 0; j < sites_.size(); ++j) {
      const Vec3 x = sites_[j] + offset;
      if (!keep(x)) continue;
      const ParticleId id = id_base_ + layers_ * id_stride_ + id_offset_ + static_cast<ParticleId>(j);
      particles.add(id, x, spec_.velocity, particle_mass_, particle_volume_, spec_.material_id);
      ++added;
    }
    ++layers_;
  }
  return added;
}

}  // namespace viscompm::particles
