// Stop requests from outside the run: SIGINT (Ctrl-C) and SIGTERM (kill, batch schedulers at
// their wall-time limit). The handler only sets a flag; the drivers poll it where they poll
// the ABORT file, write a checkpoint and return RunStatus::Interrupted. A second signal of the
// same kind while the first is being handled ends the process at once (the previous
// checkpoint stays valid: checkpoints are replaced atomically).
#pragma once
#include <string>

namespace ff {

// Installs the handlers for SIGINT and SIGTERM (idempotent). Called by the CLI only, so that a
// library user (tests, batch tools) keeps its own signal disposition.
void install_stop_signal_handlers();
// True once SIGINT or SIGTERM was received (or request_stop() was called).
bool stop_requested();
// The signal that asked to stop (0: none, or request_stop()).
int stop_signal();
// What asked to stop, for messages: "SIGINT (Ctrl-C)", "SIGTERM", "signal N", or "a stop
// request" (request_stop() without a signal, or no request).
std::string stop_signal_name();
// The signal's name when one asked to stop, else `otherwise` (what else can stop a child run: an
// ABORT file): for the batch commands' messages about stopped cases.
std::string stop_cause_or(const std::string& otherwise);
// Sets the flag from code (tests); `signal` is what stop_signal() then reports.
void request_stop(int signal = 0);
// Clears the flag (tests that run several drivers in one process).
void clear_stop_request();

}  // namespace ff
