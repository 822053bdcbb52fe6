// A run stopped by a signal that reaches one rank only abandons the current step on every rank
// at its next Newton iteration and writes a checkpoint from which --restart continues bit for
// bit (like a run that wrote a checkpoint there and went on); wall-clock checkpoints replace
// each other; a step that goes non-finite is retried with a smaller Δt and, when that cannot
// help, ends the run with SimulationError and the frames written so far intact.
#include <gtest/gtest.h>

#include <csignal>
#include <filesystem>
#include <sstream>
#include <stdexcept>

#include "gather.hpp"
#include "scenes.hpp"
#include "viscompm/core/error.hpp"
#include "viscompm/io/checkpoint.hpp"
#include "viscompm/io/frame_writer.hpp"
#include "viscompm/io/particle_file.hpp"
#include "viscompm/simulation/simulation.hpp"
#include "viscompm/core/stop_request.hpp"

using namespace viscompm;

namespace {
// The default scene, coarse, three short frames, writing into `directory`.
scene::SceneConfig short_run(const std::string& directory) {
  auto scene = scene::read_scene(VISCOMPM_SOURCE_DIR "/inputs/scenes/shooting_sponge.xml",
                                 {{"Grid/Cell size", "0.06"}, {"Newton/Tolerance", "1e-10"},
                                  {"Simulation/Frame rate", "120"}, {"Simulation/Frames", "3"}});
  scene.output.directory = directory;
  return scene;
}


std::vector<std::string> files_starting_with(const std::string& directory, const std::string& prefix) {
  std::vector<std::string> found;
  for (const auto& entry : std::filesystem::directory_iterator(directory))
    if (entry.path().filename().string().rfind(prefix, 0) == 0) found.push_back(entry.path().string());
  return found;
}

// A model that behaves like another but writes NaN into F after steps longer than `limit`: a
// stand-in for a constitutive update that breaks down at large steps.
class BreaksAtLargeSteps : public materials::Material {
 public:
  BreaksAtLargeSteps(std::unique_ptr<materials::Material> inner, double limit)
      : Material(inner->name()), inner_(std::move(inner)), limit_(limit) {}
  std::string model() const override { return inner_->model(); }
  double density() const override { return inner_->density(); }
  double wave_speed() const override { return inner_->wave_speed(); }
  std::vector<std::string> state_fields() const override { return inner_->state_fields(); }
  bool evaluate(const particles::ParticleSet& ps, std::size_t p, const Mat3& A, const materials::StepContext& step,
                int order, materials::PotentialDerivatives& out) const override {
    return inner_->evaluate(ps, p, A, step, order, out);
  }
  void update_state(particles::ParticleSet& ps, std::size_t p, const Mat3& A,
                    const materials::StepContext& step) const override {
    inner_->update_state(ps, p, A, step);
    if (step.dt > limit_) ps.deformation_gradient[p](0, 0) = std::numeric_limits<double>::quiet_NaN();
  }
  Mat3 left_cauchy_green_elastic(const particles::ParticleSet& ps, std::size_t p) const override {
    return inner_->left_cauchy_green_elastic(ps, p);
  }

 private:
  std::unique_ptr<materials::Material> inner_;
  double limit_;
};

materials::MaterialList breaking_materials(const scene::SceneConfig& scene, double limit) {
  materials::MaterialList list = simulation::make_materials(scene);
  for (auto& m : list) m = std::make_unique<BreaksAtLargeSteps>(std::move(m), limit);
  return list;
}

// A checkpoint resets what the solver reuses across steps, as a restart starts afresh: the
// reference writes one after every step (wall-clock checkpoints every 1e-9 s), and so does the
// run that is stopped and restarted.
scene::SceneConfig every_step(scene::SceneConfig scene) {
  scene.output.checkpoint_wall_seconds = 1e-9;
  return scene;
}

// The short run never stopped, checkpointed after every step: its particles, gathered, and steps.
struct ReferenceRun {
  std::map<ParticleId, testkit::ParticleState> particles;
  std::int64_t steps;
};
ReferenceRun reference_run(const std::string& dir, const linalg::SolverConfiguration& solver,
                           const parallel::Communicator& world) {
  std::ostringstream log;
  simulation::Simulation straight(every_step(short_run(dir + "/straight")), solver, world);
  EXPECT_EQ(straight.run(log).stop_signal, 0);
  return {testkit::gather_particles(straight.particles(), world.comm()), straight.step_count()};
}
}  // namespace

TEST(StopRequest, ASignalOnOneRankStopsEveryRankWithACheckpointThatContinuesBitForBit) {
  const parallel::Communicator world(MPI_COMM_WORLD);
  const std::string dir = testkit::work_directory(world, "stop");
  const auto solver = testkit::jacobi_cg(1e-12);
  std::ostringstream log;

  const auto straight = reference_run(dir, solver, world);
  const auto& reference = straight.particles;

  // SIGTERM reaches the last rank only, before the first step: every rank abandons that step at
  // its first Newton iteration and checkpoints the state before it.
  install_stop_handlers();
  clear_stop_signal();
  if (world.rank() == world.size() - 1) std::raise(SIGTERM);
  simulation::Simulation stopped(every_step(short_run(dir + "/stopped")), solver, world);
  // Frame 0 written whole, as if the signal came right after it (a request pending while a frame
  // is written ends the write: DuringAFramesFile... below).
  stopped.frame_pieces().stop = {};
  const auto summary = stopped.run(log);
  clear_stop_signal();
  EXPECT_EQ(summary.stop_signal, SIGTERM);
  EXPECT_EQ(stopped.step_count(), 0) << "every rank abandons the step during which the signal came";
  EXPECT_EQ(summary.stop_checkpoint, dir + "/stopped/" + io::step_checkpoint_file_name(0));
  EXPECT_TRUE(std::filesystem::exists(summary.stop_checkpoint));
  EXPECT_EQ(stopped.time(), 0.0) << "stopped before the first step was taken";
  EXPECT_TRUE(files_starting_with(dir + "/stopped", "frame_00001").empty());

  simulation::Simulation continued(every_step(short_run(dir + "/stopped")), solver, world, summary.stop_checkpoint);
  EXPECT_EQ(continued.time(), stopped.time());
  const auto rest = continued.run(log);
  EXPECT_EQ(rest.stop_signal, 0);
  EXPECT_EQ(continued.step_count(), straight.steps);
  const auto result = testkit::gather_particles(continued.particles(), world.comm());
  EXPECT_TRUE(testkit::bitwise_equal(reference, result)) << "difference " << testkit::max_state_difference(reference, result);
  if (world.is_root()) EXPECT_EQ(files_starting_with(dir + "/stopped", "frame_").size(), 4u);
}

// The run's control state (stop request, wall-clock checkpoint, solver.csv's health) is agreed by
// every rank in one collective: what any rank sees, all see; the largest signal wins.
TEST(RunControl, IsAgreedByEveryRank) {
  const parallel::Communicator world(MPI_COMM_WORLD);
  simulation::RunControl local;
  EXPECT_FALSE(simulation::RunControl::agreed(local, world).stop());
  if (world.rank() == world.size() - 1) local.stop_signal = SIGINT;
  if (world.rank() == 0) local.checkpoint_due = true;
  simulation::RunControl agreed = simulation::RunControl::agreed(local, world);
  EXPECT_EQ(agreed.stop_signal, SIGINT);
  EXPECT_TRUE(agreed.stop());
  EXPECT_TRUE(agreed.checkpoint_due);
  EXPECT_FALSE(agreed.solver_log_failed);
  local = {};
  local.stop_signal = world.rank() == 0 ? SIGTERM : SIGINT;  // SIGTERM (15) > SIGINT (2)
  local.solver_log_failed = world.rank() == world.size() - 1;
  agreed = simulation::RunControl::agreed(local, world);
  EXPECT_EQ(agreed.stop_signal, SIGTERM);
  EXPECT_FALSE(agreed.checkpoint_due);
  EXPECT_TRUE(agreed.solver_log_failed);
}

// An interrupt installed on the public integrator, without run()'s after-step callback: advance_to
// returns after the abandoned step (time and step unchanged) instead of trying it for ever; it
// used to loop, here cut short by an exception after 1000 questions (issue 24).
TEST(Interrupts, EndAdvanceToWithoutAnAfterStepCallback) {
  const parallel::Communicator world(MPI_COMM_WORLD);
  const std::string dir = testkit::work_directory(world, "interrupt_without_after_step");
  simulation::Simulation sim(short_run(dir), testkit::jacobi_cg(1e-10), world);
  simulation::RunSummary summary;
  ASSERT_TRUE(sim.advance_to(0.25 / 120.0, summary));
  const double t = sim.time();
  const std::int64_t steps = sim.step_count();
  ASSERT_GT(steps, 0);
  int asked = 0;
  sim.integrator().set_interrupt([&] {
    if (++asked > 1000) throw std::runtime_error("advance_to asked the interrupt 1000 times");
    return true;
  });
  bool reached = true;
  EXPECT_NO_THROW(reached = sim.advance_to(1.0 / 120.0, summary));
  EXPECT_FALSE(reached);
  EXPECT_EQ(sim.time(), t);
  EXPECT_EQ(sim.step_count(), steps);
  EXPECT_EQ(asked, 1) << "one step tried, abandoned at its first Newton iteration";
  // Without the interrupt the same call goes on to the end.
  sim.integrator().set_interrupt({});
  EXPECT_TRUE(sim.advance_to(1.0 / 120.0, summary));
  EXPECT_EQ(sim.time(), 1.0 / 120.0);
  EXPECT_GT(sim.step_count(), steps);
}

TEST(WallClockCheckpoints, EachReplacesThePreviousAndTheRunGoesOn) {
  const parallel::Communicator world(MPI_COMM_WORLD);
  const std::string dir = testkit::work_directory(world, "wall");
  auto scene = short_run(dir);
  scene.output.checkpoint_wall_seconds = 1e-9;  // after every step
  simulation::Simulation sim(scene, testkit::jacobi_cg(1e-10), world);
  std::ostringstream log;
  const auto summary = sim.run(log);
  EXPECT_EQ(summary.stop_signal, 0);
  EXPECT_EQ(files_starting_with(dir, "frame_").size(), 4u);
  const auto checkpoints = files_starting_with(dir, "checkpoint_step_");
  ASSERT_EQ(checkpoints.size(), 1u) << "each wall-clock checkpoint replaces the previous one";
  EXPECT_EQ(checkpoints[0], dir + "/" + io::step_checkpoint_file_name(sim.step_count()));
  EXPECT_GT(sim.step_count(), 3);
  EXPECT_NE(log.str().find("checkpoint"), world.is_root() ? std::string::npos : 0u);
}

TEST(NonFiniteSteps, AreRetriedWithASmallerTimeStep) {
  const parallel::Communicator world(MPI_COMM_WORLD);
  const std::string dir = testkit::work_directory(world, "nonfinite_retry");
  const auto scene = short_run(dir);
  simulation::Simulation plain(scene, testkit::jacobi_cg(1e-10), world);
  simulation::RunSummary plain_summary;
  plain.advance_to(1.0 / 120.0, plain_summary);
  ASSERT_EQ(plain_summary.retries, 0);
  // Steps of the plain run's length break; half as long do not.
  const double limit = 0.7 * plain.time() / plain_summary.steps;

  simulation::Simulation sim(scene, breaking_materials(scene, limit), testkit::jacobi_cg(1e-10), world);
  simulation::RunSummary summary;
  sim.advance_to(1.0 / 120.0, summary);
  EXPECT_GT(summary.retries, 0) << "no step went non-finite: the test would not see a retry";
  EXPECT_GT(summary.steps, plain_summary.steps);
  EXPECT_EQ(sim.time(), 1.0 / 120.0);
  bool finite = true;
  for (std::size_t p = 0; p < sim.particles().size(); ++p)
    finite &= sim.particles().deformation_gradient[p].allFinite() && sim.particles().position[p].allFinite();
  EXPECT_FALSE(world.any(!finite));
}

TEST(NonFiniteSteps, EndTheRunWithTheFramesWrittenSoFarIntact) {
  const parallel::Communicator world(MPI_COMM_WORLD);
  const std::string dir = testkit::work_directory(world, "nonfinite_fail");
  auto scene = short_run(dir);
  scene.simulation.min_time_step = 1e-4;
  simulation::Simulation sim(scene, breaking_materials(scene, 0.0), testkit::jacobi_cg(1e-10), world);  // every step
  std::ostringstream log;
  std::string message;
  try {
    sim.run(log);
  } catch (const SimulationError& e) {
    message = e.what();
  }
  EXPECT_NE(message.find("non-finite"), std::string::npos) << message;
  EXPECT_NE(message.find("frame 0"), std::string::npos) << message;
  if (world.is_root()) {
    EXPECT_EQ(files_starting_with(dir, "frame_").size(), 1u);
    EXPECT_TRUE(files_starting_with(dir, "frame_00000.h5.tmp").empty());
  }
  // Frame 0 reads back whole and finite.
  io::FileAttributes attributes;
  const auto frame0 = io::read_particle_file(dir + "/" + io::frame_file_name(0), world, attributes);
  EXPECT_EQ(world.sum(static_cast<std::int64_t>(frame0.size())), world.sum(static_cast<std::int64_t>(sim.particles().size())));
  bool finite = true;
  for (std::size_t p = 0; p < frame0.size(); ++p) finite &= frame0.deformation_gradient[p].allFinite();
  EXPECT_FALSE(world.any(!finite));
}

// Issue 24: a stop request that reaches one rank while the scene's meshes are read (a mesh's level
// set, the long part of setting a run up) ends reading on every rank at the same stage, with
// StopRequested: no rank goes on to the run's first collective to wait there for one that left
// (it used to: the signalled rank ended, the others hung until killed).
TEST(StopRequest, DuringAMeshsLevelSetReachesEveryRankBeforeTheNextCollective) {
  const parallel::Communicator world(MPI_COMM_WORLD);
  const std::string toothpaste = VISCOMPM_SOURCE_DIR "/inputs/scenes/paper/toothpaste.xml";
  const std::vector<scene::Override> coarse = {{"Colliders/toothbrush/Voxel size", "0.02"}};
  install_stop_handlers();
  clear_stop_signal();
  if (world.rank() == world.size() - 1) std::raise(SIGUSR1);
  int stopped = 0;
  try {
    (void)scene::read_scene(toothpaste, coarse, world);
  } catch (const StopRequested& e) {
    stopped = e.signal;
  }
  clear_stop_signal();
  EXPECT_EQ(stopped, SIGUSR1) << "rank " << world.rank() << " did not stop with the others";
  // Every rank is here, at the same collective; without a request the same reading completes.
  EXPECT_EQ(world.sum(std::int64_t{stopped != 0}), world.size());
  scene::SceneConfig scene;
  EXPECT_NO_THROW(scene = scene::read_scene(toothpaste, coarse, world));
  ASSERT_EQ(scene.colliders.size(), 1u);
  EXPECT_TRUE(scene.colliders[0].field != nullptr);
}

namespace {
// Whether `path` exists, as rank 0 sees it, on every rank.
bool exists_on_root(const parallel::Communicator& world, const std::string& path) {
  return world.any(world.is_root() && std::filesystem::exists(path));
}
}  // namespace

// Issue 24: a frame's particle file is written in pieces, between which the ranks agree on a stop
// request. A request that reaches the last rank in the middle of frame 1's file ends the write on
// every rank at the same piece, the partial file is removed, and the run stops as after a step:
// a checkpoint from which --restart writes frame 1 and goes on, bit for bit as a run never
// stopped. (Before, a frame was written whole whatever came: a 7-GB frame outlived the grace of
// a batch system's SIGTERM.)
TEST(StopRequest, DuringAFramesFileRemovesThePartialFileAndStopsEveryRank) {
  const parallel::Communicator world(MPI_COMM_WORLD);
  const std::string dir = testkit::work_directory(world, "stop_during_frame");
  const auto solver = testkit::jacobi_cg(1e-12);
  std::ostringstream log;
  const auto straight = reference_run(dir, solver, world);
  const auto& reference = straight.particles;

  install_stop_handlers();
  clear_stop_signal();
  simulation::Simulation stopped(every_step(short_run(dir + "/stopped")), solver, world);
  io::WritePieces& pieces = stopped.frame_pieces();
  pieces.rows = 16;
  const std::function<int()> signal_of_this_rank = pieces.stop;
  int asked = 0;  // in frame 1's file
  pieces.stop = [&] {
    if (stopped.time() > 0.0 && ++asked == 5 && world.rank() == world.size() - 1) std::raise(SIGTERM);
    return signal_of_this_rank();
  };
  ASSERT_GT(world.max(static_cast<std::int64_t>(stopped.particles().size())), 5 * 16) << "too few pieces";
  const auto summary = stopped.run(log);
  clear_stop_signal();
  EXPECT_EQ(summary.stop_signal, SIGTERM);
  EXPECT_EQ(asked, 5) << "every rank ends the write at the piece after which the request came";
  EXPECT_EQ(stopped.time(), 1.0 / 120.0) << "stopped at frame 1's time, its steps taken";
  EXPECT_FALSE(exists_on_root(world, dir + "/stopped/" + io::frame_file_name(1)));
  EXPECT_FALSE(exists_on_root(world, dir + "/stopped/" + io::frame_file_name(1) + ".tmp")) << "the partial file";
  EXPECT_TRUE(exists_on_root(world, dir + "/stopped/" + io::frame_file_name(0)));
  EXPECT_EQ(summary.stop_checkpoint, dir + "/stopped/" + io::step_checkpoint_file_name(stopped.step_count()));
  EXPECT_TRUE(exists_on_root(world, summary.stop_checkpoint));

  simulation::Simulation continued(every_step(short_run(dir + "/stopped")), solver, world, summary.stop_checkpoint);
  const auto rest = continued.run(log);
  EXPECT_EQ(rest.stop_signal, 0);
  EXPECT_EQ(continued.step_count(), straight.steps);
  const auto result = testkit::gather_particles(continued.particles(), world.comm());
  EXPECT_TRUE(testkit::bitwise_equal(reference, result)) << "difference " << testkit::max_state_difference(reference, result);
  for (int frame = 0; frame <= 3; ++frame)
    EXPECT_TRUE(exists_on_root(world, dir + "/stopped/" + io::frame_file_name(frame))) << "frame " << frame;
}

// A request agreed while frame 0 is written ends the run as one during its set-up: StopRequested
// on every rank, no frame, no checkpoint (nothing was simulated).
TEST(StopRequest, DuringFrameZerosFileEndsTheRunAsDuringItsSetUp) {
  const parallel::Communicator world(MPI_COMM_WORLD);
  const std::string dir = testkit::work_directory(world, "stop_during_frame_zero");
  install_stop_handlers();
  clear_stop_signal();
  simulation::Simulation sim(short_run(dir), testkit::jacobi_cg(1e-10), world);
  io::WritePieces& pieces = sim.frame_pieces();
  pieces.rows = 16;
  const std::function<int()> signal_of_this_rank = pieces.stop;
  int asked = 0;
  pieces.stop = [&] {
    if (++asked == 3 && world.is_root()) std::raise(SIGINT);
    return signal_of_this_rank();
  };
  std::ostringstream log;
  int stopped = 0;
  try {
    sim.run(log);
  } catch (const StopRequested& e) {
    stopped = e.signal;
  }
  clear_stop_signal();
  EXPECT_EQ(stopped, SIGINT);
  EXPECT_EQ(asked, 3);
  EXPECT_EQ(sim.step_count(), 0);
  if (world.is_root()) {
    EXPECT_TRUE(files_starting_with(dir, "frame_").empty());
    EXPECT_TRUE(files_starting_with(dir, "checkpoint").empty());
  }
}
