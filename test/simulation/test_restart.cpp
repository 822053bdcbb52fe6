// Checkpoint and restart: restarting at a frame and running on gives the particles of the run
// that went straight through — bit for bit on the same rank count, to solver tolerance on
// another — and a file written by all ranks is read back identically by one.
#include <gtest/gtest.h>

#include <filesystem>

#include "gather.hpp"
#include "scenes.hpp"
#include "viscompm/io/checkpoint.hpp"
#include "viscompm/io/frame_writer.hpp"
#include "viscompm/io/particle_file.hpp"
#include "viscompm/simulation/simulation.hpp"

using namespace viscompm;

namespace {
// The default scene, coarse, with tight solver tolerances, writing into `directory`.
scene::SceneConfig restart_scene(const std::string& directory) {
  auto scene = scene::read_scene(VISCOMPM_SOURCE_DIR "/inputs/scenes/shooting_sponge.xml",
                                 {{"Grid/Cell size", "0.06"}, {"Newton/Tolerance", "1e-10"},
                                  {"Grid/Rebalance threshold", "1.02"}});
  scene.output.directory = directory;
  return scene;
}

}  // namespace

TEST(Restart, ContinuesBitForBitOnTheSameRankCountAndToToleranceOnOne) {
  const parallel::Communicator world(MPI_COMM_WORLD);
  const std::string dir = testkit::work_directory(world, "restart");
  const auto scene = restart_scene(dir);
  const auto solver = testkit::jacobi_cg(1e-12);
  const double t_checkpoint = 2.0 / scene.simulation.frame_rate, t_end = 4.0 / scene.simulation.frame_rate;

  // Straight through, with a checkpoint on the way.
  simulation::Simulation straight(scene, solver, world);
  simulation::RunSummary summary;
  straight.advance_to(t_checkpoint, summary);
  const std::string checkpoint = straight.write_checkpoint();
  straight.advance_to(t_end, summary);
  const auto reference = testkit::gather_particles(straight.particles(), world.comm());

  simulation::Simulation restarted(scene, solver, world, checkpoint);
  EXPECT_EQ(restarted.time(), t_checkpoint);
  restarted.advance_to(t_end, summary);
  const auto continued = testkit::gather_particles(restarted.particles(), world.comm());
  EXPECT_TRUE(testkit::bitwise_equal(reference, continued)) << "difference " << testkit::max_state_difference(reference, continued);
  EXPECT_EQ(restarted.step_count(), straight.step_count());

  // The checkpoint of all ranks, continued on rank 0 alone.
  if (MPI_Comm solo = testkit::solo_communicator(); solo != MPI_COMM_NULL) {
    simulation::Simulation alone(scene, solver, parallel::Communicator(solo), checkpoint);
    simulation::RunSummary s;
    alone.advance_to(t_end, s);
    const auto single = testkit::gather_particles(alone.particles(), solo);
    EXPECT_LT(testkit::max_state_difference(reference, single), 1e-8);
    MPI_Comm_free(&solo);
  }
}

TEST(Restart, AFileWrittenByAllRanksIsReadBackIdenticallyByOne) {
  const parallel::Communicator world(MPI_COMM_WORLD);
  const std::string dir = testkit::work_directory(world, "readback");
  const auto scene = restart_scene(dir);
  simulation::Simulation sim(scene, testkit::jacobi_cg(1e-10), world);
  simulation::RunSummary summary;
  sim.advance_to(1.0 / scene.simulation.frame_rate, summary);
  const auto written = testkit::gather_particles(sim.particles(), world.comm());
  io::write_frame(dir, {1, sim.time(), sim.step_count(), 0}, sim.particles(), sim.materials(), world);
  const std::string file = dir + "/" + io::frame_file_name(1);
  if (MPI_Comm solo = testkit::solo_communicator(); solo != MPI_COMM_NULL) {
    io::FileAttributes attributes;
    const auto read = io::read_particle_file(file, parallel::Communicator(solo), attributes);
    EXPECT_TRUE(testkit::bitwise_equal(written, testkit::gather_particles(read, solo)));
    EXPECT_EQ(attributes.reals.at("time"), sim.time());
    EXPECT_EQ(attributes.integers.at("frame"), 1);
    MPI_Comm_free(&solo);
  }
}
