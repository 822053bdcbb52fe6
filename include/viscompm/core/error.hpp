// The two ways a run ends early, mapped to the exit codes of the CLI contract (DESIGN.md §4).
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

/// The simulation cannot continue (Newton failed at the smallest time step, NaN, ...).
/// Frames already written stay intact. Exit code 3.
class SimulationError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

inline constexpr int exit_success = 0;
inline constexpr int exit_bad_input = 2;
inline constexpr int exit_simulation_failed = 3;

}  // namespace viscompm
