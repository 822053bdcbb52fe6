#include <Teuchos_TimeMonitor.hpp>
#include <cstdlib>
#include <filesystem>
#include <iostream>

#include "viscompm/app/malloc_tuning.hpp"
#include "viscompm/app/run_program.hpp"
#include "viscompm/core/error.hpp"
#include "viscompm/linalg/environment.hpp"
#include "viscompm/scene/command_line.hpp"
#include "viscompm/study/solver_study.hpp"

namespace viscompm::app {

namespace {
std::string describe_study_parameters() {
  std::string text = "\nStudy parameters (STUDY.xml, addressable by --set):\n";
  for (const auto& s : study::StudySettings::table().specs())
    text += "  " + s.name + " (" + ParameterSpec::type_name(s.type) + ", " + s.range_text() + "): " + s.doc + "\n";
  return text;
}

// The plot scripts, installed beside the program: BIN/../share/viscompm/scripts (the build tree
// has the same layout).
std::string plot_script(const std::string& name) {
  std::error_code error;
  const std::filesystem::path program = std::filesystem::canonical("/proc/self/exe", error);
  return (program.parent_path() / VISCOMPM_DATA_FROM_BIN / "scripts" / name).lexically_normal().string();
}
}  // namespace

int run_study_program(int argc, char** argv) {
  run_with_huge_pages(argv);
  linalg::Environment environment(&argc, &argv);
  const parallel::Communicator comm(MPI_COMM_WORLD);
  const bool root = comm.is_root();
  return run_with_exit_codes("viscompm-study", comm, [&] {
    scene::ProgramOptions options;
    options.program = "viscompm-study";
    options.input_name = "STUDY.xml";
    options.description =
        "viscompm-study: solve the same Newton systems (of a scene at several resolutions and time steps,\n"
        "or MatrixMarket files) with several solver configurations (Mode = systems: DIR/study.csv,\n"
        "DIR/operators.csv, DIR/study.png), or run whole frames of a scene once per configuration\n"
        "(Mode = steps: DIR/steps.csv, DIR/steps.png). Exit codes: 0 success, 2 bad input, 3 failure.";
    options.frames = false;
    options.restart = false;
    options.solver = false;
    options.output_parameter = "Output directory";
    options.epilogue = describe_study_parameters();
    const scene::CommandLine cl = scene::parse_command_line(argc, argv, options);
    if (cl.help) {
      if (root) std::cout << cl.help_text;
      return exit_success;
    }
    const study::StudySettings settings = study::read_study(cl.input_file, cl.overrides);
    const int rows = study::run_study(settings, cl.input_file, comm, std::cout);
    // Where the lean cycles' and the deflation's time went (all configurations that used them).
    if (!Teuchos::TimeMonitor::lookupCounter("viscompm: lean cycle: 1 line smoother").is_null())
      Teuchos::TimeMonitor::summarize(std::cout, false, true, false, Teuchos::Union, "viscompm: lean cycle");
    if (!Teuchos::TimeMonitor::lookupCounter("viscompm: deflation: projections").is_null())
      Teuchos::TimeMonitor::summarize(std::cout, false, true, false, Teuchos::Union, "viscompm: deflation");
    const bool steps = settings.mode == study::StudyMode::steps;
    const std::string csv = settings.output_directory + (steps ? "/steps.csv" : "/study.csv");
    if (root) {
      std::cout << "wrote " << rows << " rows to " << csv << "\n";
      if (settings.plot) {
        // Debian's matplotlib belongs to the system Python.
        const std::string python = std::filesystem::exists("/usr/bin/python3") ? "/usr/bin/python3" : "python3";
        const std::string command = python + " " + plot_script(steps ? "plot_steps.py" : "plot_study.py") + " " +
                                    csv + " " + settings.output_directory + (steps ? "/steps.png" : "/study.png");
        if (std::system(command.c_str()) != 0)
          std::cerr << "viscompm-study: no plot (needs python3 with matplotlib): " << command << "\n";
      }
    }
    return exit_success;
  });
}

}  // namespace viscompm::app
