// The denoiser's time per megapixel (docs/DENOISING.md): NFOR on the film of a 4-spp path-traced
// render of the built-in Cornell box at 1024x1024, at 1 and 2 threads. Run:
//   build/release/bench/tracer_denoise_bench [--benchmark_filter=...]
#include <benchmark/benchmark.h>

#include "accel/accelerator.hpp"
#include "denoise/nfor.hpp"
#include "film/feature_film.hpp"
#include "film/framebuffer.hpp"
#include "render/render_image.hpp"
#include "scene/builtin.hpp"

namespace tracer {
namespace {

constexpr int kSize = 1024;

const FeatureFilm& film() {
  static const FeatureFilm f = [] {
    const Scene scene = make_cornell_box();
    RenderSettings s;
    s.integrator = Integrator::Path;
    s.width = s.height = kSize;
    s.spp = 4;
    Framebuffer image(kSize, kSize);
    FeatureFilm features(kSize, kSize);
    PassContext ctx{&scene, Camera(*scene.camera, kSize, kSize), s, &image};
    ctx.features = &features;
    RenderMonitor control;
    render_round(build_accelerator(scene, AccelOptions{}), ctx, sample_passes(s), SchedOptions{}, control);
    return features;
  }();
  return f;
}

void BM_Nfor(benchmark::State& state) {
  const FeatureFilm& f = film();
  const Executor executor(Strategy::Tbb, int(state.range(0)));
  for (auto _ : state) benchmark::DoNotOptimize(denoise::nfor(f, executor));
  state.counters["s/Mpixel"] = benchmark::Counter(
      double(kSize) * double(kSize) / 1e6, benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_Nfor)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(5.0);

}  // namespace
}  // namespace tracer

BENCHMARK_MAIN();
