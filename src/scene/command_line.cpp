#include "viscompm/scene/command_line.hpp"

#include <Teuchos_CommandLineProcessor.hpp>
#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <map>
#include <sstream>

#include "viscompm/core/error.hpp"

namespace viscompm::scene {

namespace {
// What the user typed, before Teuchos parses the options it knows: "--name value" joined into
// "--name=value", the input file and the repeatable --set taken out, --help noted.
struct RawArguments {
  std::vector<std::string> options = {""};  ///< argv[0] and the options for Teuchos
  std::vector<Override> sets;
  std::map<std::string, int> given;  ///< options that take one value: each given once
  bool help = false;
};

RawArguments collect(int argc, const char* const* argv, const ProgramOptions& options, CommandLine& cl) {
  RawArguments raw;
  raw.options[0] = argv[0];
  for (int i = 1; i < argc; ++i) {
    std::string arg = argv[i];
    if (arg == "--help" || arg == "-h") {
      raw.help = true;
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
    const std::string name = arg.substr(0, arg.find('='));
    if (name == "--set") {
      raw.sets.push_back(Override::parse(arg.substr(6)));
      continue;
    }
    if (++raw.given[name] > 1) throw InputError("command line: option " + name + " is given more than once (give it once)");
    raw.options.push_back(arg);
  }
  return raw;
}

// --frames N: a whole number of frames, not negative.
void check_frames(const std::string& frames) {
  char* end = nullptr;
  errno = 0;
  const long n = std::strtol(frames.c_str(), &end, 10);
  if (frames.empty() || end != frames.c_str() + frames.size() || errno == ERANGE || n < 0 ||
      n > std::numeric_limits<int>::max())
    throw InputError("command line: option --frames: '" + frames + "' is not a number of frames (0 to " +
                     std::to_string(std::numeric_limits<int>::max()) + ")");
}

// Each parameter is set once: a --set that repeats another, or that an option already sets
// (--output, --frames, --solver), would silently replace it.
void check_set_once(const std::vector<Override>& overrides, const std::vector<std::string>& sources) {
  for (std::size_t a = 0; a < overrides.size(); ++a)
    for (std::size_t b = 0; b < a; ++b)
      if (overrides[a].path == overrides[b].path)
        throw InputError("command line: '" + overrides[a].path + "' is set twice (" + sources[b] + " and " +
                         sources[a] + ")");
}
}  // namespace

CommandLine parse_command_line(int argc, const char* const* argv, const ProgramOptions& options) {
  CommandLine cl;
  std::string output, solver, restart, set_doc;
  std::string frames;  // empty: not given
  Teuchos::CommandLineProcessor clp(false, true);
  clp.setDocString(options.description.c_str());
  clp.setOption("output", &output, ("output directory (overrides " + options.output_parameter + ")").c_str());
  clp.setOption("set", &set_doc, "\"Path/To/Parameter=value\": override one input parameter (repeatable)");
  if (options.frames) clp.setOption("frames", &frames, "number of frames (overrides Simulation/Frames)");
  if (options.solver) clp.setOption("solver", &solver, "solver XML (overrides Solver/File)");
  if (options.restart) clp.setOption("restart", &restart, "continue from this checkpoint");

  RawArguments raw = collect(argc, argv, options, cl);
  if (raw.help) {
    std::ostringstream text;
    clp.printHelpMessage((options.program + " " + options.input_name).c_str(), text);
    text << options.epilogue;
    cl.help = true;
    cl.help_text = text.str();
    return cl;
  }
  std::vector<char*> args;
  for (auto& s : raw.options) args.push_back(s.data());
  std::ostringstream errors;
  const auto result = clp.parse(static_cast<int>(args.size()), args.data(), &errors);
  if (result != Teuchos::CommandLineProcessor::PARSE_SUCCESSFUL) {
    std::string message = errors.str();
    for (char& ch : message)
      if (ch == '\n') ch = ' ';
    throw InputError("bad command line: " + (message.empty() ? std::string("see --help") : message));
  }
  if (cl.input_file.empty()) throw InputError("missing " + options.input_name + " (see --help)");
  cl.overrides = raw.sets;
  std::vector<std::string> sources(cl.overrides.size(), "--set");
  auto add = [&](const std::string& path, const std::string& value, const std::string& option) {
    cl.overrides.push_back({path, value});
    sources.push_back(option);
  };
  if (!output.empty()) add(options.output_parameter, output, "--output");
  if (raw.given.count("--frames")) {
    check_frames(frames);
    add(options.frames_parameter, frames, "--frames");
  }
  // The scene resolves Solver/File relative to itself; --solver is relative to where we are.
  if (!solver.empty()) add("Solver/File", std::filesystem::absolute(solver).string(), "--solver");
  check_set_once(cl.overrides, sources);
  if (raw.given.count("--restart")) {
    if (restart.empty()) throw InputError("command line: option --restart: needs a checkpoint file");
    cl.restart_file = restart;
  }
  return cl;
}

}  // namespace viscompm::scene
