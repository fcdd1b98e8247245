#include "driver/prepare_render.hpp"

#include "base/stopwatch.hpp"
#include "driver/output_checks.hpp"
#include "driver/render_options.hpp"
#include "driver/scene_setup.hpp"

namespace tracer::driver {

PreparedRender::PreparedRender(const RenderArgs& args, const PrepareOptions& options) {
  validate(args);
  if (options.writes_outputs) check_outputs(args);
  thread_limit = ThreadLimit(args.threads.value_or(0));
  WideBvh::force_simd_target(simd_target_for(args));
  const auto t_load = Clock::now();
  scene = load_scene(args.scene, options.quiet, options.cancel, &load_phases);
  load_ms = ms_since(t_load);
  if (options.writes_outputs) check_outputs_against_inputs(args);
  camera = camera_for(scene, args);
  settings = settings_for(args, scene, lighting_note);
  sched = sched_options_for(args);
  AccelOptions accel_options = accel_options_for(args);
  if (!args.build_quality && accel_options.kind == AccelKind::Bvh8)
    accel_options.quality = default_build_quality(settings, args.frames, scene.size());
  accel_options.bvh.cancel = options.cancel;
  accel = build_accelerator(scene, accel_options);
}

}  // namespace tracer::driver
