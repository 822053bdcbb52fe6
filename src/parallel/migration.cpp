#include "viscompm/parallel/migration.hpp"

namespace viscompm::parallel {

int particle_owner(const Decomposition& decomposition, const grid::GridGeometry& geometry,
                   grid::KernelOrder order, const Vec3& x) {
  return decomposition.owner_of_cell(grid::stencil_base(order, (x - geometry.origin) / geometry.dx));
}

std::size_t migrate_particles(const Communicator& comm, const Decomposition& decomposition,
                              const grid::GridGeometry& geometry, grid::KernelOrder order,
                              particles::ParticleSet& particles) {
  const int ranks = comm.size();
  if (ranks == 1) return 0;
  std::vector<std::vector<double>> outgoing(ranks);
  std::vector<std::size_t> keep;
  keep.reserve(particles.size());
  for (std::size_t p = 0; p < particles.size(); ++p) {
    const int owner = particle_owner(decomposition, geometry, order, particles.position[p]);
    if (owner == comm.rank()) keep.push_back(p);
    else particles::pack_particle(particles, p, outgoing[owner]);
  }
  const std::size_t sent = particles.size() - keep.size();
  particles.permute(keep);
  for (const auto& incoming : comm.exchange(outgoing)) particles::unpack_particles(incoming, particles);
  return sent;
}

}  // namespace viscompm::parallel
