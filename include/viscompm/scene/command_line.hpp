// Command lines of the programs (doc/contracts.md), parsed with Teuchos::CommandLineProcessor:
//   PROGRAM INPUT.xml [--output DIR] [--frames N] [--solver SOLVER.xml] [--set "Path=value"]...
//           [--restart CHECKPOINT.h5] [--help]
// "--option value" and "--option=value" are both accepted; --set may repeat.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "viscompm/scene/scene.hpp"

namespace viscompm::scene {

struct CommandLine {
  std::string input_file;               ///< the scene (or study) XML
  std::optional<std::string> restart_file;  ///< --restart, if given (never empty)
  std::vector<Override> overrides;      ///< --set, then --output, --frames and --solver as overrides
  bool help = false;
  std::string help_text;                ///< filled when help is true
};

struct ProgramOptions {
  std::string program;                  ///< e.g. "viscompm"
  std::string description;              ///< first lines of --help
  std::string input_name = "SCENE.xml";
  bool frames = true;                   ///< accepts --frames
  bool solver = true;                   ///< accepts --solver
  bool restart = true;                  ///< accepts --restart
  std::string output_parameter = "Output/Directory";
  std::string frames_parameter = "Simulation/Frames";
  std::string epilogue;                 ///< appended to --help (e.g. the parameter list)
};

/// Parses argv. Throws InputError (exit code 2) on bad usage.
CommandLine parse_command_line(int argc, const char* const* argv, const ProgramOptions& options);

}  // namespace viscompm::scene
