#include "viscompm/parallel/ghost_particles.hpp"

#include <algorithm>

namespace viscompm::parallel {

std::size_t append_ghost_particles(const Communicator& comm, const NodePartition& partition,
                                   const grid::GridLayout& layout, particles::ParticleSet& particles) {
  if (comm.size() == 1) return 0;
  const int width = grid::stencil_width(layout.order);
  std::vector<std::vector<double>> outgoing(comm.size());
  std::vector<int> destinations;
  for (std::size_t c = 0; c < layout.own_cell_count; ++c) {
    // The owners of the cell's stencil nodes, other than this rank.
    const Int3 base = layout.geometry.node_index(layout.cells[c]);
    destinations.clear();
    for (int z = 0; z < width; ++z)
      for (int y = 0; y < width; ++y)
        for (int x = 0; x < width; ++x) {
          const int owner = partition.owner(base + Int3(x, y, z));
          if (owner != comm.rank() && std::find(destinations.begin(), destinations.end(), owner) == destinations.end())
            destinations.push_back(owner);
        }
    for (const int r : destinations)
      for (std::size_t p = layout.cell_begin[c]; p < layout.cell_begin[c + 1]; ++p)
        particles::pack_particle(particles, p, outgoing[r]);
  }
  const std::size_t before = particles.size();
  for (const auto& incoming : comm.exchange(outgoing)) particles::unpack_particles(incoming, particles);
  return particles.size() - before;
}

}  // namespace viscompm::parallel
