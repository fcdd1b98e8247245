// The setup every front end (tracer render, tracer view, tracer-mpi) makes from its flags, in one
// order: check the flags and the outputs, limit the threads, pick the SIMD target, load the scene, check the outputs
// against what the load read, then the camera, the settings, the scheduler and the accelerator.
#pragma once

#include <string>

#include "frontend/render_args.hpp"
#include "parallel/thread_count.hpp"

namespace tracer::frontend {

struct PrepareOptions {
  bool writes_outputs = true;   // this process writes -o and --stats-json (tracer-mpi: rank 0 only)
  bool quiet = false;           // no loader warnings
  CancelFlag cancel = nullptr;  // polled by the load and the build
};

// Everything a render needs before its first pass. Built in place, never moved or copied: the
// accelerator points into the scene. Throws UsageError (a flag) or InputError (a file).
struct PreparedRender {
  PreparedRender(const RenderArgs& args, const PrepareOptions& options);
  PreparedRender(const PreparedRender&) = delete;
  PreparedRender& operator=(const PreparedRender&) = delete;

  ThreadLimit thread_limit{0};  // --threads, for the load, the build and the render
  Scene scene;
  LoadPhases load_phases;
  double load_ms = 0.0;
  CameraSpec camera;
  RenderSettings settings;
  std::string lighting_note;  // what settings_for() added for this scene (a white sky), for the user
  SchedOptions sched;
  Accelerator accel;
};

}  // namespace tracer::frontend
