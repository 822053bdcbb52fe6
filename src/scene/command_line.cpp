#include "viscompm/scene/command_line.hpp"

#include <Teuchos_CommandLineProcessor.hpp>
#include <filesystem>
#include <limits>
#include <sstream>

#include "viscompm/core/error.hpp"

namespace viscompm::scene {

CommandLine parse_command_line(int argc, const char* const* argv, const ProgramOptions& options) {
  CommandLine cl;
  std::string output, solver, restart, set_doc;
  std::string frames;  // empty: not given
  bool help = false;
  Teuchos::CommandLineProcessor clp(false, true);
  clp.setDocString(options.description.c_str());
  clp.setOption("output", &output, ("output directory (overrides " + options.output_parameter + ")").c_str());
  clp.setOption("set", &set_doc, "\"Path/To/Parameter=value\": override one input parameter (repeatable)");
  if (options.frames) clp.setOption("frames", &frames, "number of frames (overrides Simulation/Frames)");
  if (options.solver) clp.setOption("solver", &solver, "solver XML (overrides Solver/File)");
  if (options.restart) clp.setOption("restart", &restart, "continue from this checkpoint");

  // Teuchos takes --name=value; accept "--name value" too, take the positional input file and
  // collect the repeatable --set ourselves.
  std::vector<std::string> normalized = {argv[0]};
  for (int i = 1; i < argc; ++i) {
    std::string arg = argv[i];
    if (arg == "--help" || arg == "-h") {
      help = true;
      continue;
    }
    if (arg.rfind("--", 0) != 0) {
      if (!cl.input_file.empty()) throw InputError("unexpected argument '" + arg + "' (one " + options.input_name + " only)");
      cl.input_file = arg;
      continue;
    }
    if (arg.find('=') == std::string::npos) {
      if (i + 1 >= argc) throw InputError("option " + arg + " needs a value");
      arg += "=" + std::string(argv[++i]);
    }
    if (arg.rfind("--set=", 0) == 0) {
      cl.overrides.push_back(Override::parse(arg.substr(6)));
      continue;
    }
    normalized.push_back(arg);
  }
  if (help) {
    std::ostringstream text;
    clp.printHelpMessage((options.program + " " + options.input_name).c_str(), text);
    text << options.epilogue;
    cl.help = true;
    cl.help_text = text.str();
    return cl;
  }
  std::vector<char*> args;
  for (auto& s : normalized) args.push_back(s.data());
  std::ostringstream errors;
  const auto result = clp.parse(static_cast<int>(args.size()), args.data(), &errors);
  if (result != Teuchos::CommandLineProcessor::PARSE_SUCCESSFUL) {
    std::string message = errors.str();
    for (char& ch : message)
      if (ch == '\n') ch = ' ';
    throw InputError("bad command line: " + (message.empty() ? std::string("see --help") : message));
  }
  if (cl.input_file.empty()) throw InputError("missing " + options.input_name + " (see --help)");
  if (!output.empty()) cl.overrides.push_back({options.output_parameter, output});
  if (!frames.empty()) cl.overrides.push_back({options.frames_parameter, frames});
  // The scene resolves Solver/File relative to itself; --solver is relative to where we are.
  if (!solver.empty()) cl.overrides.push_back({"Solver/File", std::filesystem::absolute(solver).string()});
  cl.restart_file = restart;
  return cl;
}

}  // namespace viscompm::scene
