#include "viscompm/app/run_program.hpp"

#include <Teuchos_DefaultComm.hpp>
#include <Teuchos_TimeMonitor.hpp>
#include <cstring>
#include <iostream>

#include "viscompm/app/malloc_tuning.hpp"
#include "viscompm/core/error.hpp"
#include "viscompm/linalg/environment.hpp"
#include "viscompm/scene/command_line.hpp"
#include "viscompm/simulation/simulation.hpp"
#include "viscompm/core/stop_request.hpp"

namespace viscompm::app {

int run_with_exit_codes(const std::string& program, const parallel::Communicator& comm,
                        const std::function<int()>& body) {
  try {
    return body();
  } catch (const InputError& e) {
    if (comm.is_root()) std::cerr << program << ": " << e.what() << std::endl;
    return exit_bad_input;
  } catch (const SimulationError& e) {
    if (comm.is_root()) std::cerr << program << ": failed: " << e.what() << std::endl;
    return exit_simulation_failed;
  } catch (const StopRequested& e) {
    // While the run was set up or wrote frame 0 (every rank agreed): nothing simulated, nothing
    // to continue from.
    if (comm.is_root())
      std::cerr << program << ": stopped by signal " << e.signal << " (" << strsignal(e.signal)
                << ") before the first step, while the run was set up; nothing was simulated" << std::endl;
    return exit_interrupted;
  } catch (const std::exception& e) {
    std::cerr << program << ": internal error on rank " << comm.rank() << ": " << e.what() << std::endl;
    MPI_Abort(MPI_COMM_WORLD, exit_simulation_failed);
    return exit_simulation_failed;
  }
}

int run_simulation_program(int argc, char** argv) {
  run_with_huge_pages(argv);
  linalg::Environment environment(&argc, &argv);
  install_stop_handlers();
  const parallel::Communicator comm(MPI_COMM_WORLD);
  const bool root = comm.is_root();
  return run_with_exit_codes("viscompm", comm, [&] {
    scene::ProgramOptions options;
    options.program = "viscompm";
    options.description =
        "viscompm: implicit Material Point Method for viscoelastic fluids, foams and sponges (Ram 2015),\n"
        "with the Newton systems assembled into Tpetra and solved by Belos CG.\n"
        "Writes DIR/frame_NNNNN.h5, DIR/particles.xdmf and DIR/solver.csv.\n"
        "Exit codes: 0 success, 2 bad input, 3 the simulation failed, 4 stopped by SIGTERM or SIGINT after\n"
        "writing a checkpoint (continue with --restart).";
    options.epilogue = "\nScene parameters (sections of SCENE.xml, addressable by --set):\n" +
                       scene::describe_scene_parameters();
    const scene::CommandLine cl = scene::parse_command_line(argc, argv, options);
    if (cl.help) {
      if (root) std::cout << cl.help_text;
      return exit_success;
    }
    const scene::SceneConfig scene = scene::read_scene(cl.input_file, cl.overrides, comm);
    const linalg::SolverConfiguration solver = scene::solver_configuration(scene);
    simulation::Simulation simulation(scene, solver, comm, cl.restart_file);
    const simulation::RunSummary summary = simulation.run(std::cout);
    if (summary.stop_signal != 0) {
      if (root)
        std::cerr << "viscompm: stopped by signal " << summary.stop_signal << " (" << strsignal(summary.stop_signal)
                  << ") at t = " << simulation.time() << ", step " << simulation.step_count() << "; continue with --restart "
                  << summary.stop_checkpoint << std::endl;
      return exit_interrupted;
    }
    Teuchos::TimeMonitor::summarize(std::cout, false, true, false, Teuchos::Union, "viscompm:");
    if (root)
      std::cout << "done: " << summary.steps << " steps, " << summary.newton_iterations << " Newton iterations, "
                << summary.linear_iterations << " CG iterations, " << summary.retries << " retries in "
                << summary.wall_seconds << " s\n"
                << "assemblies: " << summary.assemblies << ", preconditioner set-ups: " << summary.preconditioner_setups
                << "; graph builds: " << summary.graph_builds << " in " << summary.steps << " steps ("
                << double(summary.graph_builds) / std::max<std::int64_t>(summary.steps, 1) << " per step)\n"
                << "per step: " << summary.owned_node_steps / std::max<std::int64_t>(summary.steps, 1)
                << " grid nodes, " << summary.shared_node_steps / std::max<std::int64_t>(summary.steps, 1)
                << " ghost nodes, " << summary.ghost_particle_steps / std::max<std::int64_t>(summary.steps, 1)
                << " ghost particles, " << double(summary.particles_migrated) / std::max<std::int64_t>(summary.steps, 1)
                << " particles migrated; " << summary.particles_deleted << " particles deleted, "
                << summary.rebalances << " rebalances\n"
                << "output: " << scene.output.directory << "/particles.xdmf (ParaView), frame_*.h5, solver.csv\n";
    if (const auto* choice = simulation.integrator().solver_choice(); choice != nullptr && root) {
      std::cout << solver.label() << ":";
      for (std::size_t k = 0; k < solver.candidates().size(); ++k)
        std::cout << (k == 0 ? " " : ", ") << solver.candidates()[k].label() << " " << choice->systems()[k] << " systems";
      std::cout << "; " << choice->trials() << " trials, " << choice->switches() << " switches, "
                << choice->warm_ups() << " second trial steps after a fresh set-up, " << choice->abandoned()
                << " solves given up at their budget, " << choice->confirmations()
                << " steps of the chosen one after a regime change\n";
    }
    return exit_success;
  });
}

}  // namespace viscompm::app
