#include "frontend/prepare_render.hpp"

#include "base/stopwatch.hpp"
#include "frontend/memory_estimate.hpp"
#include "frontend/output_checks.hpp"
#include "frontend/render_options.hpp"
#include "frontend/scene_setup.hpp"

namespace tracer::frontend {

PreparedRender::PreparedRender(const RenderArgs& args, const PrepareOptions& options) {
  validate(args);
  if (options.writes_outputs) check_outputs(args);
  thread_limit = ThreadLimit(args.threads.value_or(0));
  // Memory is checked before it is taken: the film from the flags alone, the scene (a glTF's
  // instances before they are expanded) with what its accelerator will need, then the whole.
  const uint64_t memory = memory_limit(args.scene);
  check_film_fits(args, memory);
  const AccelOptions planned = accel_options_for(args);
  const uint64_t accel_per_triangle =
      build_bytes_per_triangle(planned.kind, args.build_quality ? planned.quality : BuildQuality::High);
  const auto t_load = Clock::now();
  scene = load_scene(args.scene, options.quiet, options.cancel, &load_phases,
                     {.bytes = memory,
                      .accel_bytes_per_triangle = accel_per_triangle,
                      .keep_instances = traces_instances(planned.kind)});
  load_ms = ms_since(t_load);
  if (options.writes_outputs) check_outputs_against_inputs(args);
  camera = camera_for(scene, args);
  settings = settings_for(args, scene, lighting_note);
  sched = sched_options_for(args);
  AccelOptions accel_options = accel_options_for(args);
  if (!args.build_quality && accel_options.kind == AccelKind::Bvh8)
    accel_options.quality = default_build_quality(settings, args.frames, scene.size());
  accel_options.bvh.cancel = options.cancel;
  check_render_fits(scene, accel_options, args, memory);
  accel = build_accelerator(scene, accel_options);
}

}  // namespace tracer::frontend
