#include "core/interrupt.hpp"

#include <csignal>

namespace caplab::core {

namespace {

volatile std::sig_atomic_t requested = 0;

extern "C" void record_stop(int signal) { requested = signal; }

}  // namespace

void install_stop_handlers() {
  struct sigaction action {};
  action.sa_handler = record_stop;
  sigemptyset(&action.sa_mask);
  action.sa_flags = SA_RESETHAND;  // a second signal takes the default action: the process ends
  for (int s : {SIGINT, SIGTERM}) sigaction(s, &action, nullptr);
}

int stop_signal() { return requested; }

std::string signal_name(int signal) {
  if (signal == SIGINT) return "SIGINT";
  if (signal == SIGTERM) return "SIGTERM";
  return "signal " + std::to_string(signal);
}

}  // namespace caplab::core
