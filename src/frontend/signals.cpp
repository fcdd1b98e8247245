#include "frontend/signals.hpp"

#include <unistd.h>

#include <csignal>

#include "io/image_io.hpp"

namespace tracer::frontend {
namespace {

std::atomic<bool> g_stop{false};
std::atomic<int> g_signal{0};

extern "C" void on_stop_signal(int sig) {
  int expected = 0;
  if (!g_signal.compare_exchange_strong(expected, sig)) {
    remove_pending_temp_file();  // async-signal-safe: one unlink()
    ::_exit(128 + expected);
  }
  g_stop.store(true);
}

const char* g_immediate_message = nullptr;

extern "C" void on_immediate_stop_signal(int sig) {
  if (g_immediate_message) {
    size_t n = 0;
    while (g_immediate_message[n]) ++n;
    [[maybe_unused]] const ssize_t w = ::write(STDERR_FILENO, g_immediate_message, n);
  }
  remove_pending_temp_file();
  ::_exit(128 + sig);
}

}  // namespace

void install_immediate_stop_handlers(const char* message) {
  g_immediate_message = message;
  struct sigaction sa {};
  sa.sa_handler = on_immediate_stop_signal;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = 0;
  for (int sig : {SIGINT, SIGTERM, SIGHUP}) sigaction(sig, &sa, nullptr);
  if (const int sig = g_signal.load()) on_immediate_stop_signal(sig);
}

void install_stop_handlers() {
  struct sigaction sa {};
  sa.sa_handler = on_stop_signal;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = 0;  // no SA_RESTART: a blocking read returns, and the loader sees the flag
  for (int sig : {SIGINT, SIGTERM, SIGHUP}) sigaction(sig, &sa, nullptr);
}

const std::atomic<bool>& stop_requested() { return g_stop; }
int stop_signal() { return g_signal.load(); }
int exit_code_for_stop() { return 128 + stop_signal(); }

const char* stop_signal_name() {
  switch (stop_signal()) {
    case SIGTERM:
      return "terminated";
    case SIGHUP:
      return "hung up";
    default:
      return "interrupted";
  }
}

}  // namespace tracer::frontend
