// The programs' bodies, so that apps/ holds thin mains: environment, command line, input,
// run, and the mapping of failures to exit codes (0 success, 2 bad input, 3 failed run).
#pragma once

namespace viscompm::app {

int run_simulation_program(int argc, char** argv);
int run_study_program(int argc, char** argv);

}  // namespace viscompm::app
