// The ways a run ends early, mapped to the exit codes of the command-line contract
// (doc/contracts.md).
#pragma once

#include <stdexcept>
#include <string>

namespace viscompm {

/// Bad input: a file that cannot be read, an unknown or ill-typed parameter, a value out of
/// range. The message is one line naming the file and the parameter. Exit code 2.
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// The one line of bad input at a parameter: "FILE: parameter 'PATH': REASON" (PATH is the
/// parameter's sublist path, e.g. "Bodies/sponge/Material"). Every such message is made here.
inline InputError parameter_error(const std::string& file, const std::string& path, const std::string& reason) {
  return InputError(file + ": parameter '" + path + "': " + reason);
}

/// The simulation cannot continue (a step failed at the smallest time step, a write failed, ...).
/// Frames and checkpoints already written stay intact. Exit code 3.
class SimulationError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A stop request (SIGTERM, SIGINT, SIGUSR1: core/stop_request.hpp) that ended a computation which
/// has no state worth a checkpoint (setting the run up). Exit code 4.
class StopRequested : public std::runtime_error {
 public:
  explicit StopRequested(int signal_number)
      : std::runtime_error("stopped by signal " + std::to_string(signal_number)), signal(signal_number) {}
  int signal;
};

inline constexpr int exit_success = 0;
inline constexpr int exit_bad_input = 2;
inline constexpr int exit_simulation_failed = 3;
/// Stopped on request (SIGTERM, SIGINT) after writing a checkpoint: --restart continues.
inline constexpr int exit_interrupted = 4;

}  // namespace viscompm
