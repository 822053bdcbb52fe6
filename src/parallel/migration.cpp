#include "viscompm/parallel/migration.hpp"

#include <numeric>

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

  std::vector<int> send_counts(ranks), recv_counts(ranks), send_offsets(ranks), recv_offsets(ranks);
  std::vector<double> send_buffer;
  for (int r = 0; r < ranks; ++r) {
    send_offsets[r] = static_cast<int>(send_buffer.size());
    send_counts[r] = static_cast<int>(outgoing[r].size());
    send_buffer.insert(send_buffer.end(), outgoing[r].begin(), outgoing[r].end());
  }
  MPI_Alltoall(send_counts.data(), 1, MPI_INT, recv_counts.data(), 1, MPI_INT, comm.comm());
  std::exclusive_scan(recv_counts.begin(), recv_counts.end(), recv_offsets.begin(), 0);
  std::vector<double> recv_buffer(recv_offsets.back() + recv_counts.back());
  MPI_Alltoallv(send_buffer.data(), send_counts.data(), send_offsets.data(), MPI_DOUBLE, recv_buffer.data(),
                recv_counts.data(), recv_offsets.data(), MPI_DOUBLE, comm.comm());
  particles::unpack_particles(recv_buffer, particles);
  return sent;
}

}  // namespace viscompm::parallel
