// viscompm SCENE.xml [--output DIR] [--frames N] [--solver SOLVER.xml] [--set "Path=value"]...
// Exit codes: 0 success, 2 bad input, 3 simulation failed, 4 stopped by a signal after a
// checkpoint (doc/contracts.md).
#include <iostream>

#include "viscompm/app/run_program.hpp"

int main(int argc, char** argv) { return viscompm::app::run_simulation_program(argc, argv); }
