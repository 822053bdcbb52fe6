// One rank and N ranks agree: the same assembled Newton matrix (global ids, values to rounding)
// and the same particles after full steps (to solver tolerance). The reference runs on a
// communicator holding rank 0 alone, inside the same test.
#include <gtest/gtest.h>

#include <map>

#include "scenes.hpp"
#include "viscompm/simulation/simulation.hpp"

using namespace viscompm;

namespace {
struct ParticleState {
  Vec3 x, v;
  Mat3 F, b, C;
};

// All particles of the communicator, by id, on every rank.
std::map<ParticleId, ParticleState> gather_particles(const particles::ParticleSet& ps, MPI_Comm comm) {
  std::vector<double> local;
  for (std::size_t p = 0; p < ps.size(); ++p) {
    local.push_back(static_cast<double>(ps.id[p]));
    for (const Vec3* v : {&ps.position[p], &ps.velocity[p]}) local.insert(local.end(), v->data(), v->data() + 3);
    for (const Mat3* m : {&ps.deformation_gradient[p], &ps.left_cauchy_green_ob[p], &ps.affine_velocity[p]})
      local.insert(local.end(), m->data(), m->data() + 9);
  }
  int ranks = 1, count = static_cast<int>(local.size());
  MPI_Comm_size(comm, &ranks);
  std::vector<int> counts(ranks), offsets(ranks, 0);
  MPI_Allgather(&count, 1, MPI_INT, counts.data(), 1, MPI_INT, comm);
  for (int r = 1; r < ranks; ++r) offsets[r] = offsets[r - 1] + counts[r - 1];
  std::vector<double> all(offsets.back() + counts.back());
  MPI_Allgatherv(local.data(), count, MPI_DOUBLE, all.data(), counts.data(), offsets.data(), MPI_DOUBLE, comm);
  std::map<ParticleId, ParticleState> out;
  for (std::size_t k = 0; k < all.size(); k += 34) {
    ParticleState s;
    s.x = Eigen::Map<const Vec3>(&all[k + 1]);
    s.v = Eigen::Map<const Vec3>(&all[k + 4]);
    s.F = Eigen::Map<const Mat3>(&all[k + 7]);
    s.b = Eigen::Map<const Mat3>(&all[k + 16]);
    s.C = Eigen::Map<const Mat3>(&all[k + 25]);
    EXPECT_TRUE(out.emplace(static_cast<ParticleId>(all[k]), s).second) << "duplicate id " << all[k];
  }
  return out;
}

// Rank 0 alone, and every rank: the reference and the run under test.
MPI_Comm solo_communicator() {
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm solo;
  MPI_Comm_split(MPI_COMM_WORLD, rank == 0 ? 0 : MPI_UNDEFINED, 0, &solo);
  return solo;
}

using Entries = std::vector<std::tuple<long long, long long, double>>;

Entries first_newton_matrix(const parallel::Communicator& comm, std::int64_t& particle_count) {
  simulation::Simulation sim(testkit::sponge_scene(), testkit::jacobi_cg(1e-12), comm);
  auto& integrator = sim.integrator();
  integrator.build_layout(sim.particles());
  integrator.particles_to_grid(sim.particles());
  const auto objective = integrator.build_objective(sim.particles(), 0.0, 4e-3);
  integrator.newton_system().assemble(*objective->potential, objective->initial_guess, true);
  particle_count = comm.sum(static_cast<std::int64_t>(sim.particles().size()));
  return integrator.newton_system().gather_entries();
}
}  // namespace

TEST(ParallelAgreement, AssembledMatrixIsTheSameOnOneRankAndOnAll) {
  const parallel::Communicator world(MPI_COMM_WORLD);
  std::int64_t n_world = 0, n_solo = 0;
  const Entries all = first_newton_matrix(world, n_world);
  Entries reference;
  if (MPI_Comm solo = solo_communicator(); solo != MPI_COMM_NULL) {
    reference = first_newton_matrix(parallel::Communicator(solo), n_solo);
    MPI_Comm_free(&solo);
  }
  if (!world.is_root()) return;
  EXPECT_EQ(n_world, n_solo);
  ASSERT_EQ(all.size(), reference.size());
  double scale = 0.0, worst = 0.0;
  for (std::size_t k = 0; k < all.size(); ++k) {
    ASSERT_EQ(std::get<0>(all[k]), std::get<0>(reference[k]));
    ASSERT_EQ(std::get<1>(all[k]), std::get<1>(reference[k]));
    scale = std::max(scale, std::abs(std::get<2>(reference[k])));
    worst = std::max(worst, std::abs(std::get<2>(all[k]) - std::get<2>(reference[k])));
  }
  EXPECT_LT(worst, 1e-13 * scale);
  EXPECT_GT(all.size(), 10000u);
}

TEST(ParallelAgreement, FullStepsAreTheSameOnOneRankAndOnAll) {
  const parallel::Communicator world(MPI_COMM_WORLD);
  const double t_end = 0.02;  // several steps: migration, graph rebuilds, bullet contact
  simulation::Simulation sim(testkit::sponge_scene(), testkit::jacobi_cg(1e-12), world);
  simulation::RunSummary summary;
  sim.advance_to(t_end, summary);
  const auto all = gather_particles(sim.particles(), world.comm());
  std::map<ParticleId, ParticleState> reference;
  if (MPI_Comm solo = solo_communicator(); solo != MPI_COMM_NULL) {
    simulation::Simulation solo_sim(testkit::sponge_scene(), testkit::jacobi_cg(1e-12), parallel::Communicator(solo));
    simulation::RunSummary solo_summary;
    solo_sim.advance_to(t_end, solo_summary);
    EXPECT_EQ(solo_summary.steps, summary.steps);
    reference = gather_particles(solo_sim.particles(), solo);
    MPI_Comm_free(&solo);
  }
  if (!world.is_root()) return;
  ASSERT_EQ(all.size(), reference.size());
  double dx = 0.0, dv = 0.0, dF = 0.0, db = 0.0, speed = 0.0;
  for (const auto& [id, s] : reference) {
    const auto it = all.find(id);
    ASSERT_NE(it, all.end()) << "particle " << id << " missing";
    dx = std::max(dx, (it->second.x - s.x).norm());
    dv = std::max(dv, (it->second.v - s.v).norm());
    dF = std::max(dF, (it->second.F - s.F).norm());
    db = std::max(db, (it->second.b - s.b).norm());
    speed = std::max(speed, s.v.norm());
  }
  EXPECT_GT(speed, 0.1);
  EXPECT_LT(dx, 1e-9);
  EXPECT_LT(dv, 1e-7 * speed);
  EXPECT_LT(dF, 1e-8);
  EXPECT_LT(db, 1e-8);
}
