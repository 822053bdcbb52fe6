// viscompm-study STUDY.xml [--output DIR] [--set "Parameter=value"]...
// Exit codes: 0 success, 2 bad input, 3 failure (doc/contracts.md).
#include "viscompm/app/run_program.hpp"

int main(int argc, char** argv) { return viscompm::app::run_study_program(argc, argv); }
