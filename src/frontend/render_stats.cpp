#include "frontend/render_stats.hpp"

#include <sys/resource.h>

#include <cinttypes>
#include <cstdio>
#include <iostream>

#include "base/text.hpp"
#include "io/image_io.hpp"

namespace tracer::frontend {

namespace {

// The process's peak resident memory so far, MiB (Linux reports ru_maxrss in KiB).
double peak_rss_mib() {
  rusage usage{};
  if (getrusage(RUSAGE_SELF, &usage) != 0) return 0.0;
  return double(usage.ru_maxrss) / 1024.0;
}

// What lights the image, in words: the lights it has, and the sky tracer adds to a path render of a
// scene without an emissive surface (settings_for), said so that it is never taken for the file's.
std::string lighting(const Scene& scene, const RenderSettings& settings, const RenderArgs& args) {
  std::string out;
  const auto add = [&](const std::string& part) { out += (out.empty() ? "" : ", ") + part; };
  if (!scene.emitters.empty()) add(std::to_string(scene.emitters.size()) + " emissive triangles");
  const auto count = [&](LightKind kind, const char* name) {
    size_t n = 0;
    for (const Light& l : scene.lights) n += l.kind == kind ? 1 : 0;
    if (n) add(std::to_string(n) + " " + name + (n > 1 ? "s" : ""));
  };
  count(LightKind::Point, "point light");
  count(LightKind::Spot, "spot light");
  count(LightKind::Directional, "directional light");
  if (settings.integrator == Integrator::Path || settings.integrator == Integrator::Whitted) {
    if (!scene.environment_map.empty()) add("an environment map");
    const Vec3 sky = settings.environment;
    if (max_component(sky) > 0.0f) {
      char text[96];
      std::snprintf(text, sizeof text, "a uniform sky (%g, %g, %g)", double(sky.x), double(sky.y), double(sky.z));
      add(text);
      if (!args.env && scene.emitters.empty() && scene.environment_map.empty()) {
        out += " added by tracer: the scene has no emissive surface (--env 0,0,0 for none)";
      }
    }
  } else if (settings.ambient > 0.0f) {
    add("ambient " + format_number(settings.ambient));
  }
  return out.empty() ? "none" : out;
}

}  // namespace

nlohmann::json render_stats(const Scene& scene, const RenderSettings& settings, const Accelerator& accel,
                            const SchedOptions& sched, const RenderArgs& args, double load_ms, double render_ms,
                            const RayCounts& rays, const LoadPhases* load_phases, const QueryCounts* traversal) {
  const double mrays = render_ms > 0 ? double(rays.total()) / (render_ms * 1e3) : 0.0;
  nlohmann::json j = {{"scene", scene.source},
                      {"triangles", scene.size()},
                      {"instances", scene.instances.size()},
                      {"placed_triangles", scene.instanced_size()},
                      {"width", settings.width},
                      {"height", settings.height},
                      {"ao_samples", settings.ao_samples},
                      {"accel", accel.name},
                      {"packets", settings.packets},
                      {"streams", settings.streams},
                      {"sched", name_of<Strategy>(kStrategyNames, sched.strategy)},
                      {"threads", thread_count(sched)},
                      {"load_ms", load_ms},
                      {"build_ms", accel.build_ms},
                      {"render_ms", render_ms},
                      {"integrator", name_of<Integrator>(kIntegratorNames, settings.integrator)},
                      {"lighting", lighting(scene, settings, args)},
                      {"max_depth", settings.max_depth},
                      {"spp", settings.spp},
                      {"frames", args.frames},
                      // Samples taken: one camera ray each (adaptive sampling skips pixels that have converged).
                      {"samples_per_s", render_ms > 0 ? double(rays.primary) / (render_ms * 1e-3) : 0.0},
                      {"noise_threshold", settings.integrator == Integrator::Path ? settings.noise_threshold : 0.0f},
                      {"min_spp", settings.min_spp},
                      {"rays",
                       {{"primary", rays.primary},
                        {"shadow", rays.shadow},
                        {"ao", rays.ao},
                        {"secondary", rays.secondary},
                        {"total", rays.total()}}},
                      {"mrays_per_s", mrays},
                      {"accel_bytes", accel.memory_bytes()},
                      {"peak_rss_mib", peak_rss_mib()},
                      {"output", args.output}};
  if (load_phases) {
    j["load_phases_ms"] = {{"read", load_phases->read_ms},
                           {"parse", load_phases->parse_ms},
                           {"textures", load_phases->textures_ms},
                           {"assembly", load_phases->assembly_ms}};
  }
  if (traversal) {
    const auto per_ray = [](const TraversalCounts& c) {
      const double n = c.rays > 0 ? double(c.rays) : 1.0;
      return nlohmann::json{{"rays", c.rays},
                            {"nodes_per_ray", double(c.nodes) / n},
                            {"packs_per_ray", double(c.packs) / n},
                            {"triangles_per_ray", double(c.triangles) / n}};
    };
    j["traversal"] = {{"closest_hit", per_ray(traversal->closest)}, {"any_hit", per_ray(traversal->any)}};
  }
  return j;
}

void print_stats(const nlohmann::json& j, const Accelerator& accel) {
  const auto str = [&](const char* k) { return j[k].get<std::string>(); };
  if (j["instances"].get<size_t>() > 0) {
    std::printf("scene        %s (%" PRIu64 " triangles: %zu unique, placed by %zu instances)\n", str("scene").c_str(),
                j["placed_triangles"].get<uint64_t>(), j["triangles"].get<size_t>(), j["instances"].get<size_t>());
  } else {
    std::printf("scene        %s (%zu triangles)\n", str("scene").c_str(), j["triangles"].get<size_t>());
  }
  const std::string integrator = str("integrator");
  const std::string depth = std::to_string(j["max_depth"].get<int>());
  std::string workload = integrator == "ao"        ? std::to_string(j["ao_samples"].get<int>()) + " AO rays per hit"
                         : integrator == "whitted" ? "whitted, at most " + depth + " reflections/refractions"
                                                   : "path, " + std::to_string(j["spp"].get<int>()) +
                                                         " samples per pixel, at most " + depth + " bounces";
  if (integrator == "path" && j["noise_threshold"].get<double>() > 0.0) {
    const double pixels = double(j["width"].get<int>()) * j["height"].get<int>() * j["frames"].get<int>();
    char adaptive[160];
    std::snprintf(adaptive, sizeof adaptive, " (adaptive: noise threshold %g, %.1f taken on average)",
                  j["noise_threshold"].get<double>(), double(j["rays"]["primary"].get<uint64_t>()) / pixels);
    workload += adaptive;
  }
  std::printf("image        %dx%d, %s -> %s\n", j["width"].get<int>(), j["height"].get<int>(), workload.c_str(),
              str("output").c_str());
  std::printf("lighting     %s\n", str("lighting").c_str());
  // An instanced scene's tree holds its unique triangles and its instances: bytes per placed
  // triangle, the figure beside a flat scene's (one instance of a triangle costs next to nothing).
  const size_t instances = j["instances"].get<size_t>();
  const double placed = double(j["placed_triangles"].get<uint64_t>());
  std::printf("accelerator  %s, %.*f bytes/%s%s\n", str("accel").c_str(), instances ? 3 : 1,
              double(j["accel_bytes"].get<size_t>()) / placed, instances ? "placed triangle" : "triangle",
              !j["packets"].get<bool>() ? ""
              : accel.kind == AccelKind::Bvh8
                  ? (j["streams"].get<bool>() ? ", primary rays in 4x4 packets, AO rays in sorted streams"
                                              : ", primary rays in 4x4 packets, AO rays in bundles")
              : is_embree(accel.kind)
                  ? (j["streams"].get<bool>() ? ", packet API: rtcIntersect16 per 4x4 block, rtcOccluded16 for shadow "
                                                "rays, rtcOccluded1M for sorted AO streams"
                                              : ", packet API: rtcIntersect16 per 4x4 block, rtcOccluded16")
                  : ", AO rays in bundles");
  std::printf("memory       %.1f MiB accelerator, %.1f MiB peak resident (scene, accelerator, image)\n",
              double(j["accel_bytes"].get<size_t>()) / (1024.0 * 1024.0), j["peak_rss_mib"].get<double>());
  if (const std::optional<BvhStats> st = accel.bvh_stats()) {
    std::printf("bvh          %zu nodes, %zu leaves (%.2f triangles avg, %zu max), depth %zu, SAH cost %.2f\n",
                st->nodes, st->leaves, st->avg_leaf_size, st->max_leaf_size, st->max_depth, st->sah_cost);
  }
  std::printf("scheduler    %s, %d threads\n", str("sched").c_str(), j["threads"].get<int>());
  std::printf("load         %10.2f ms", j["load_ms"].get<double>());
  if (j.contains("load_phases_ms")) {
    const auto& p = j["load_phases_ms"];
    std::printf("  (read %.2f, parse %.2f, textures %.2f, assembly %.2f)", p["read"].get<double>(),
                p["parse"].get<double>(), p["textures"].get<double>(), p["assembly"].get<double>());
  }
  std::printf("\n");
  std::printf("build        %10.2f ms\n", j["build_ms"].get<double>());
  std::printf("render       %10.2f ms\n", j["render_ms"].get<double>());
  if (j.contains("denoise_ms")) std::printf("denoise      %10.2f ms\n", j["denoise_ms"].get<double>());
  const auto& r = j["rays"];
  std::printf("rays         %llu primary, %llu shadow, %llu AO, %llu reflected/refracted/bounced, %llu total\n",
              r["primary"].get<unsigned long long>(), r["shadow"].get<unsigned long long>(),
              r["ao"].get<unsigned long long>(), r["secondary"].get<unsigned long long>(),
              r["total"].get<unsigned long long>());
  std::printf("throughput   %10.2f Mrays/s", j["mrays_per_s"].get<double>());
  if (integrator == "path") std::printf(", %.3f Msamples/s", j["samples_per_s"].get<double>() * 1e-6);
  std::printf("\n");
  if (j.contains("traversal")) {
    for (const auto& [key, title] : {std::pair{"closest_hit", "closest hit"}, {"any_hit", "any hit"}}) {
      const auto& t = j["traversal"][key];
      std::printf("traversal    %-11s %6.2f nodes, %5.2f leaf packs, %6.2f triangles per ray (%llu rays)\n", title,
                  t["nodes_per_ray"].get<double>(), t["packs_per_ray"].get<double>(),
                  t["triangles_per_ray"].get<double>(), t["rays"].get<unsigned long long>());
    }
  }
}

void write_stats_json(const std::string& path, const nlohmann::json& j) {
  if (path.empty()) return;
  if (path == "-") {
    std::cout << j.dump(2) << "\n" << std::flush;
  } else {
    write_file_atomic(path, j.dump(2) + "\n");
  }
}

}  // namespace tracer::frontend
