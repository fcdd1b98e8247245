// Ctrl-C (SIGINT), SIGTERM and SIGHUP stop a run the same way: the first sets a flag that the
// load, the builders and the render loop poll, and the run ends with exit code 128 + the signal
// number; a second one ends the process at once, removing the temporary file of an image write
// in progress. Only kill -9 (which no process can handle) can leave that file behind.
#pragma once

#include <atomic>

namespace tracer::cli {

void install_stop_handlers();
const std::atomic<bool>& stop_requested();
int stop_signal();               // the first signal received, 0 if none
int exit_code_for_stop();        // 128 + stop_signal()
const char* stop_signal_name();  // "interrupted", "terminated", "hung up"

}  // namespace tracer::cli
