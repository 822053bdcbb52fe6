#include "viscompm/core/stop_request.hpp"

#include <csignal>

namespace viscompm {

namespace {
volatile std::sig_atomic_t received = 0;

extern "C" void record_signal(int signal_number) {
  if (received != 0) {
    // The second request: stop now, as without a handler.
    std::signal(signal_number, SIG_DFL);
    std::raise(signal_number);
    return;
  }
  received = signal_number;
}
}  // namespace

void install_stop_handlers() {
  struct sigaction action = {};
  action.sa_handler = record_signal;
  sigemptyset(&action.sa_mask);
  action.sa_flags = SA_RESTART;  // system calls (MPI, HDF5) continue where they were
  sigaction(SIGTERM, &action, nullptr);
  sigaction(SIGINT, &action, nullptr);
  sigaction(SIGUSR1, &action, nullptr);
  std::signal(SIGXFSZ, SIG_IGN);
}

int stop_signal() { return received; }

void clear_stop_signal() { received = 0; }

}  // namespace viscompm
