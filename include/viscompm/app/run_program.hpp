// The programs' bodies, so that apps/ holds thin mains: environment, command line, input,
// run, and the mapping of failures to exit codes (0 success, 2 bad input, 3 failed run).
#pragma once

#include <functional>
#include <string>

#include "viscompm/parallel/communicator.hpp"

namespace viscompm::app {

/// Runs `body` and maps its failures to the exit codes, printing one line on rank 0:
/// InputError → 2, SimulationError → 3; anything else is a bug: MPI_Abort with 3.
int run_with_exit_codes(const std::string& program, const parallel::Communicator& comm,
                        const std::function<int()>& body);

int run_simulation_program(int argc, char** argv);
int run_study_program(int argc, char** argv);

}  // namespace viscompm::app
