// Ctrl-C (SIGINT), SIGTERM and SIGHUP stop a run the same way: the first sets a flag that the
// load, the builders and the render loop poll, and the run ends with exit code 128 + the signal
// number; a second one ends the process at once, removing the temporary file of an image write
// in progress. Only kill -9 (which no process can handle) can leave that file behind.
#pragma once

#include <atomic>

namespace tracer::frontend {

// The flag handlers. tracer installs them as it is loaded (cli/main.cpp's .preinit_array entry,
// before any library constructor), so that a signal is lost only in the few milliseconds of the
// dynamic loader: a shell without job control starts a background job with SIGINT ignored, and
// one that came before this call went with that. Each command then keeps them (it polls the
// flag) or, where nothing polls it, asks for the immediate ones.
void install_stop_handlers();
// For a process that cannot stop cleanly on its own (a rank of an MPI job, whose peers the
// runtime is already tearing down): the first SIGINT, SIGTERM or SIGHUP writes `message` (if not
// null) to stderr, removes the temporary file of a write in progress and exits 128 + the signal
// at once. `message` must outlive the process. A stop that came before this call ends the
// process here, the same way.
void install_immediate_stop_handlers(const char* message);
const std::atomic<bool>& stop_requested();
int stop_signal();               // the first signal received, 0 if none
int exit_code_for_stop();        // 128 + stop_signal()
const char* stop_signal_name();  // "interrupted", "terminated", "hung up"

}  // namespace tracer::frontend
