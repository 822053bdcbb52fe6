#include "viscompm/particles/regions.hpp"

namespace viscompm::particles {

std::size_t assign_region(const MaterialRegion& region, std::size_t first, ParticleSet& particles) {
  std::size_t assigned = 0;
  for (std::size_t p = first; p < particles.size(); ++p) {
    if (!region.shape.contains(particles.position[p])) continue;
    particles.material_id[p] = region.material_id;
    particles.mass[p] = region.density * particles.volume0[p];
    ++assigned;
  }
  return assigned;
}

}  // namespace viscompm::particles
