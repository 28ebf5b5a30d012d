// A stop requested from outside a run (SIGINT from Ctrl-C, SIGTERM from a batch system or
// `kill`): `caplab run` ends the step it is in, writes a checkpoint and stops, so a long run
// loses nothing and continues with `caplab run --resume`.
//
// install_stop_handlers() records the first SIGINT or SIGTERM and restores the default action
// (SA_RESETHAND), so a second one ends the process at once, as users expect of a second Ctrl-C
// (the checkpoint is written atomically: the previous one stays whole). The step loop polls
// stop_signal(); the run then throws Interrupted, and `main` ends the process by the same
// signal, so the shell or batch system that sent it sees a process stopped by it.
#pragma once

#include <string>

#include "core/error.hpp"

namespace caplab::core {

/// Installs the SIGINT and SIGTERM handlers (idempotent).
void install_stop_handlers();
/// The signal that asked the process to stop, 0 when none did.
int stop_signal();
/// "SIGINT", "SIGTERM", or "signal N".
std::string signal_name(int signal);

/// A run that stopped on request after writing its checkpoint: neither a result nor a failure
/// of the method (main ends the process by `signal()`).
class Interrupted : public Error {
 public:
  Interrupted(int signal, long step, const std::string& message) : Error(message), signal_(signal), step_(step) {}
  int signal() const { return signal_; }
  long step() const { return step_; }

 private:
  int signal_;
  long step_;
};

}  // namespace caplab::core
