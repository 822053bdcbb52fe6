// One rank and N ranks agree: the same assembled Newton matrix (global ids, values to rounding)
// and the same particles — every stored field — after full steps (to solver tolerance), for the
// sponge scene and for a scene with every constitutive model. The reference runs on a
// communicator holding rank 0 alone, inside the same test; registered on more than one rank only
// (on one rank it would compare a run with itself).
#include <gtest/gtest.h>

#include <limits>
#include <map>
#include <type_traits>

#include "gather.hpp"
#include "scenes.hpp"
#include "viscompm/simulation/simulation.hpp"

using namespace viscompm;

namespace {
// Every stored field of a particle, packed (particles::pack_particle), by id.
using ParticleStates = std::map<ParticleId, std::vector<double>>;

// All particles of the communicator, by id, on every rank, each packed (every stored field).
ParticleStates gather_packed(const particles::ParticleSet& ps, MPI_Comm comm) {
  const particles::ParticleSet all = testkit::gather_particle_set(ps, comm);
  ParticleStates out;
  for (std::size_t p = 0; p < all.size(); ++p) {
    std::vector<double> state;
    particles::pack_particle(all, p, state);
    EXPECT_TRUE(out.emplace(all.id[p], std::move(state)).second) << "duplicate id " << all.id[p];
  }
  return out;
}

// Offsets and lengths of each field in a packed particle.
std::map<std::string, std::pair<std::size_t, std::size_t>> packed_layout() {
  std::map<std::string, std::pair<std::size_t, std::size_t>> layout;
  std::size_t offset = 0;
  particles::ParticleSet().for_each_field([&](const char* name, const auto& field) {
    using T = typename std::decay_t<decltype(field)>::value_type;
    const std::size_t n = std::is_same_v<T, Mat3> ? 9 : std::is_same_v<T, Vec3> ? 3 : 1;
    layout[name] = {offset, n};
    offset += n;
  });
  return layout;
}

// The largest difference of one field over all particles.
double worst_difference(const ParticleStates& a, const ParticleStates& b, const std::string& field) {
  const auto [offset, length] = packed_layout().at(field);
  double worst = 0.0;
  for (const auto& [id, state] : b) {
    const auto it = a.find(id);
    if (it == a.end()) return std::numeric_limits<double>::infinity();
    for (std::size_t k = offset; k < offset + length; ++k) worst = std::max(worst, std::abs(it->second[k] - state[k]));
  }
  return worst;
}

// The scenes compared: the sponge (two Oldroyd-B materials, grips, a bullet) and every model at once.
scene::SceneConfig scene_named(const std::string& name) {
  return name == "sponge" ? testkit::sponge_scene() : testkit::mixed_models_scene();
}

class ParallelAgreement : public ::testing::TestWithParam<std::string> {};


using Entries = std::vector<std::tuple<long long, long long, double>>;

Entries first_newton_matrix(const std::string& scene, const parallel::Communicator& comm,
                            std::int64_t& particle_count) {
  simulation::Simulation sim(scene_named(scene), testkit::jacobi_cg(1e-12), comm);
  auto& integrator = sim.integrator();
  integrator.prepare(sim.particles(), 4e-3);
  const auto objective = integrator.build_objective(sim.particles(), 0.0, 4e-3);
  integrator.newton_system().assemble(*objective->potential, objective->initial_guess, true);
  particle_count = comm.sum(static_cast<std::int64_t>(integrator.layout().own_particle_count()));
  return integrator.newton_system().gather_entries();
}
}  // namespace

TEST_P(ParallelAgreement, AssembledMatrixIsTheSameOnOneRankAndOnAll) {
  const parallel::Communicator world(MPI_COMM_WORLD);
  std::int64_t n_world = 0, n_solo = 0;
  const Entries all = first_newton_matrix(GetParam(), world, n_world);
  Entries reference;
  if (MPI_Comm solo = testkit::solo_communicator(); solo != MPI_COMM_NULL) {
    reference = first_newton_matrix(GetParam(), parallel::Communicator(solo), n_solo);
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

TEST_P(ParallelAgreement, FullStepsAreTheSameOnOneRankAndOnAll) {
  const parallel::Communicator world(MPI_COMM_WORLD);
  const double t_end = 0.02;  // several steps: migration, graph rebuilds, contact, plastic flow
  simulation::Simulation sim(scene_named(GetParam()), testkit::jacobi_cg(1e-12), world);
  simulation::RunSummary summary;
  sim.advance_to(t_end, summary);
  const auto all = gather_packed(sim.particles(), world.comm());
  ParticleStates reference;
  if (MPI_Comm solo = testkit::solo_communicator(); solo != MPI_COMM_NULL) {
    simulation::Simulation solo_sim(scene_named(GetParam()), testkit::jacobi_cg(1e-12), parallel::Communicator(solo));
    simulation::RunSummary solo_summary;
    solo_sim.advance_to(t_end, solo_summary);
    EXPECT_EQ(solo_summary.steps, summary.steps);
    reference = gather_packed(solo_sim.particles(), solo);
    MPI_Comm_free(&solo);
  }
  if (!world.is_root()) return;
  ASSERT_EQ(all.size(), reference.size());
  double speed = 0.0;
  const auto [v_offset, v_length] = packed_layout().at("velocity");
  for (const auto& [id, state] : reference) speed = std::max(speed, Eigen::Map<const Vec3>(&state[v_offset]).norm());
  EXPECT_GT(speed, 0.1);
  EXPECT_LT(worst_difference(all, reference, "position"), 1e-9);
  EXPECT_LT(worst_difference(all, reference, "velocity"), 1e-7 * speed);
  // Every stored strain and plastic variable, whatever the model.
  for (const char* field : {"deformation_gradient", "left_cauchy_green_ob", "elastic_deformation_gradient",
                            "plastic_deformation_gradient", "equivalent_plastic_strain"})
    EXPECT_LT(worst_difference(all, reference, field), 1e-8) << field;
  EXPECT_EQ(worst_difference(all, reference, "material_id"), 0.0);
}

TEST(ParallelAgreement, TheMixedSceneExercisesEveryModelsPlasticity) {
  // The mixed scene is only a test of every model if each of them deforms, and the plastic ones flow.
  const parallel::Communicator world(MPI_COMM_WORLD);
  simulation::Simulation sim(testkit::mixed_models_scene(), testkit::jacobi_cg(1e-12), world);
  simulation::RunSummary summary;
  sim.advance_to(0.02, summary);
  const auto& ps = sim.particles();
  const auto& materials = sim.materials();
  std::vector<double> strain(materials.size(), 0.0), flowed(materials.size(), 0.0);
  for (std::size_t p = 0; p < ps.size(); ++p) {
    const int m = ps.material_id[p];
    strain[m] = std::max(strain[m], (ps.deformation_gradient[p] - Mat3::Identity()).norm());
    flowed[m] = std::max(flowed[m], ps.yield_function[p] > 0.0 ? 1.0 : 0.0);
  }
  for (std::size_t m = 0; m < materials.size(); ++m) {
    EXPECT_GT(world.max(strain[m]), 1e-3) << materials[m]->name();
    if (materials[m]->model() != "oldroyd_b" && materials[m]->model() != "neo_hookean")
      EXPECT_EQ(world.max(flowed[m]), 1.0) << materials[m]->name() << " never flowed plastically";
  }
}

INSTANTIATE_TEST_SUITE_P(Scenes, ParallelAgreement, ::testing::Values("sponge", "mixed_models"));
