// Requests to stop a run early, as batch systems send them: SIGTERM (the job's time is up, or it
// is pre-empted), SIGINT (Ctrl-C) and SIGUSR1 (which Open MPI's mpirun forwards to the ranks
// without ending the job itself). The handler only records the signal; Simulation::run looks at
// it before every Newton iteration (abandoning the step) and after every step, agrees on it
// across ranks (a signal may reach only some of them), writes a checkpoint and returns. The long
// computations of setting a run up and of its output (OpenVDB's level sets) look at it too and
// end with StopRequested (core/error.hpp). A second signal ends the process at once.
#pragma once

namespace viscompm {

/// Installs the handlers for SIGTERM, SIGINT and SIGUSR1, and ignores SIGXFSZ (a file-size limit then
/// fails the write, which ends the run with exit code 3, instead of killing the process).
void install_stop_handlers();
/// The signal number received on this rank since the handlers were installed, 0 if none.
int stop_signal();
/// Forgets a received signal (tests).
void clear_stop_signal();

}  // namespace viscompm
