#include "core/interrupt.hpp"

#include <algorithm>
#include <atomic>
#include <csignal>
#include <signal.h>

namespace ff {

namespace {
// Lock-free atomics are async-signal-safe; volatile sig_atomic_t would also do for one flag.
std::atomic<int> g_signal{-1};  // -1: no request; 0: request_stop(); >0: the signal number
static_assert(std::atomic<int>::is_always_lock_free);

extern "C" void on_stop_signal(int sig) {
  int expected = -1;
  if (!g_signal.compare_exchange_strong(expected, sig)) {
    // Second signal: give the default action back and re-raise (the user insists).
    std::signal(sig, SIG_DFL);
    std::raise(sig);
  }
}
}  // namespace

void install_stop_signal_handlers() {
  struct sigaction sa {};
  sa.sa_handler = on_stop_signal;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = SA_RESTART;  // slow system calls (file writes) continue rather than fail
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);
}

bool stop_requested() { return g_signal.load(std::memory_order_relaxed) >= 0; }
int stop_signal() { return std::max(0, g_signal.load(std::memory_order_relaxed)); }
std::string stop_signal_name() {
  switch (const int sig = stop_signal()) {
    case SIGINT: return "SIGINT (Ctrl-C)";
    case SIGTERM: return "SIGTERM";
    case 0: return "a stop request";
    default: return "signal " + std::to_string(sig);
  }
}

std::string stop_cause_or(const std::string& otherwise) { return stop_requested() ? stop_signal_name() : otherwise; }

void request_stop(int signal) { g_signal.store(signal); }
void clear_stop_request() { g_signal.store(-1); }

}  // namespace ff
