// Particles of a whole communicator, by id, for comparing runs across rank counts.
#pragma once

#include <mpi.h>

#include <map>
#include <stdexcept>

#include "viscompm/parallel/communicator.hpp"
#include "viscompm/particles/particle_set.hpp"

namespace viscompm::testkit {

struct ParticleState {
  Vec3 x, v;
  Mat3 F, b, C;
};

/// All particles of the communicator (every stored field), on every rank.
inline particles::ParticleSet gather_particle_set(const particles::ParticleSet& ps, MPI_Comm comm) {
  std::vector<double> local;
  for (std::size_t p = 0; p < ps.size(); ++p) particles::pack_particle(ps, p, local);
  particles::ParticleSet all;
  particles::unpack_particles(parallel::Communicator(comm).all_gather(local), all);
  return all;
}

/// All particles of the communicator, by id, on every rank (throws on a duplicate id).
inline std::map<ParticleId, ParticleState> gather_particles(const particles::ParticleSet& ps, MPI_Comm comm) {
  const particles::ParticleSet all = gather_particle_set(ps, comm);
  std::map<ParticleId, ParticleState> out;
  for (std::size_t p = 0; p < all.size(); ++p) {
    const ParticleState s{all.position[p], all.velocity[p], all.deformation_gradient[p], all.left_cauchy_green_ob[p],
                          all.affine_velocity[p]};
    if (!out.emplace(all.id[p], s).second) throw std::runtime_error("duplicate particle id");
  }
  return out;
}

// Rank 0 alone, and every rank: the reference and the run under test.
inline MPI_Comm solo_communicator() {
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm solo;
  MPI_Comm_split(MPI_COMM_WORLD, rank == 0 ? 0 : MPI_UNDEFINED, 0, &solo);
  return solo;
}


/// Largest difference of positions, velocities, F and b_OB between two gathered runs (throws if
/// a particle is missing from either).
inline double max_state_difference(const std::map<ParticleId, ParticleState>& a,
                                   const std::map<ParticleId, ParticleState>& b) {
  if (a.size() != b.size()) throw std::runtime_error("the runs hold different particle counts");
  double worst = 0.0;
  for (const auto& [id, s] : a) {
    const auto it = b.find(id);
    if (it == b.end()) throw std::runtime_error("particle missing from one run");
    worst = std::max({worst, (it->second.x - s.x).norm(), (it->second.v - s.v).norm(), (it->second.F - s.F).norm(),
                      (it->second.b - s.b).norm()});
  }
  return worst;
}

/// True if the two gathered runs are equal bit for bit.
inline bool bitwise_equal(const std::map<ParticleId, ParticleState>& a, const std::map<ParticleId, ParticleState>& b) {
  if (a.size() != b.size()) return false;
  for (const auto& [id, s] : a) {
    const auto it = b.find(id);
    if (it == b.end() || it->second.x != s.x || it->second.v != s.v || it->second.F != s.F || it->second.b != s.b ||
        it->second.C != s.C)
      return false;
  }
  return true;
}

}  // namespace viscompm::testkit
