#include "cli/bench.hpp"

#include <unistd.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <mutex>
#include <numeric>
#include <optional>
#include <sstream>
#include <thread>

#include "accel/accelerator.hpp"
#include "base/errors.hpp"
#include "cli/parse.hpp"
#include "cli/render_args.hpp"
#include "io/image_io.hpp"
#include "render/render_image.hpp"
#include "render/render_tile.hpp"
#include "scene/builtin.hpp"
#include "scene/camera.hpp"
#include "scene/obj_loader.hpp"
#include "scene/views.hpp"

namespace tracer::cli {
namespace {

using Clock = std::chrono::steady_clock;

struct Variant {
  std::string name;
  AccelKind accel;
  BvhSplit split;
  BuildMode build;
  SchedKind sched;
  std::string description;
  bool study;
  bool packets = false;  // primary rays in 4x4 packets (bvh8), AO rays in bundles (bvh, bvh8)
};

// The study's ten columns (its ISPC column is simd-brute, our Highway kernels) and ours.
const std::vector<Variant>& all_variants() {
  static const std::vector<Variant> v = {
      {"seq", AccelKind::Brute, BvhSplit::Median, BuildMode::Seq, SchedKind::Seq, "brute force, one thread", true},
      {"async", AccelKind::Brute, BvhSplit::Median, BuildMode::Seq, SchedKind::Async, "brute force, std::async per row",
       true},
      {"bvh", AccelKind::Bvh, BvhSplit::Median, BuildMode::Seq, SchedKind::Seq, "median BVH, one thread", true},
      {"async+bvh", AccelKind::Bvh, BvhSplit::Median, BuildMode::Seq, SchedKind::Async, "median BVH, async rows", true},
      {"async+bvh+parbuild-v1", AccelKind::Bvh, BvhSplit::Median, BuildMode::Async, SchedKind::Async,
       "median BVH built with std::async, async rows", true},
      {"lq+bvh+parbuild-v1", AccelKind::Bvh, BvhSplit::Median, BuildMode::Async, SchedKind::Queue,
       "median BVH built with std::async, locked queue", true},
      {"async+bvh+parbuild-v2", AccelKind::Bvh, BvhSplit::Median, BuildMode::Queue, SchedKind::Async,
       "median BVH built by a job queue, async rows", true},
      {"lq+bvh+parbuild-v2", AccelKind::Bvh, BvhSplit::Median, BuildMode::Queue, SchedKind::Queue,
       "median BVH built by a job queue, locked queue", true},
      {"lq", AccelKind::Brute, BvhSplit::Median, BuildMode::Seq, SchedKind::Queue, "brute force, locked queue", true},
      {"simd-brute", AccelKind::BruteSimd, BvhSplit::Median, BuildMode::Seq, SchedKind::Seq,
       "brute force, 8 triangles per SIMD test, one thread (the study's ISPC)", true},
      {"sah", AccelKind::Bvh, BvhSplit::Sah, BuildMode::Seq, SchedKind::Seq, "SAH BVH, one thread", false},
      {"async+sah", AccelKind::Bvh, BvhSplit::Sah, BuildMode::Tasks, SchedKind::Async,
       "SAH BVH (TBB build), std::async per row", false},
      {"lq+sah", AccelKind::Bvh, BvhSplit::Sah, BuildMode::Tasks, SchedKind::Queue,
       "SAH BVH (TBB build), locked queue of 64-pixel blocks", false},
      {"atomic+sah", AccelKind::Bvh, BvhSplit::Sah, BuildMode::Tasks, SchedKind::Atomic,
       "SAH BVH (TBB build), atomic tile counter", false},
      {"tbb+sah", AccelKind::Bvh, BvhSplit::Sah, BuildMode::Tasks, SchedKind::Tbb,
       "SAH BVH (TBB build), TBB work stealing", false},
      {"bvh8", AccelKind::Bvh8, BvhSplit::Sah, BuildMode::Tasks, SchedKind::Tbb,
       "8-wide SIMD BVH (TBB build), TBB work stealing", false},
      {"best", AccelKind::Bvh8, BvhSplit::Sah, BuildMode::Tasks, SchedKind::Tbb,
       "8-wide SIMD BVH (TBB build), primary-ray packets and AO bundles, TBB work stealing", false, true},
      {"embree", AccelKind::Embree, BvhSplit::Sah, BuildMode::Tasks, SchedKind::Tbb,
       "Intel Embree 3, single rays (rtcIntersect1/rtcOccluded1), TBB work stealing", false},
      {"embree-packets", AccelKind::Embree, BvhSplit::Sah, BuildMode::Tasks, SchedKind::Tbb,
       "Intel Embree 3, packets: rtcIntersect16 per 4x4 block, rtcOccluded16 for its shadow rays and for each hit's "
       "AO rays, TBB work stealing",
       false, true},
  };
  return v;
}

// The study's published milliseconds (4-core i7-7700HQ), for ratio comparison.
const std::map<std::string, std::map<std::string, double>>& study_ms() {
  static const std::map<std::string, std::map<std::string, double>> m = {
      {"Original",
       {{"seq", 9867.0},
        {"async", 2271.0},
        {"bvh", 4043.3},
        {"async+bvh", 1034.0},
        {"async+bvh+parbuild-v1", 1047.7},
        {"lq+bvh+parbuild-v1", 1244.3},
        {"async+bvh+parbuild-v2", 958.3},
        {"lq+bvh+parbuild-v2", 1254.3},
        {"lq", 2714.0},
        {"simd-brute", 4476.0}}},
      {"Mirror",
       {{"seq", 9865.0},
        {"async", 2271.3},
        {"bvh", 4037.0},
        {"async+bvh", 1030.7},
        {"async+bvh+parbuild-v1", 1052.7},
        {"lq+bvh+parbuild-v1", 1243.3},
        {"async+bvh+parbuild-v2", 958.7},
        {"lq+bvh+parbuild-v2", 1253.0},
        {"lq", 2713.0},
        {"simd-brute", 4334.0}}},
      {"Sphere",
       {{"seq", 463005.0},
        {"async", 116098.0},
        {"bvh", 3708.0},
        {"async+bvh", 1078.0},
        {"async+bvh+parbuild-v1", 1131.0},
        {"lq+bvh+parbuild-v1", 1182.7},
        {"async+bvh+parbuild-v2", 1016.3},
        {"lq+bvh+parbuild-v2", 1147.3},
        {"lq", 129371.3},
        {"simd-brute", 150822.3}}},
      {"Water",
       {{"seq", 1482647.0},
        {"async", 373939.0},
        {"bvh", 4489.0},
        {"async+bvh", 1528.3},
        {"async+bvh+parbuild-v1", 1747.7},
        {"lq+bvh+parbuild-v1", 1638.0},
        {"async+bvh+parbuild-v2", 1607.7},
        {"lq+bvh+parbuild-v2", 1512.7},
        {"lq", 417250.3}}},
  };
  return m;
}

// One row of the tables: a view (camera and light from the views file), a scene framed from
// outside its bounds (an OBJ path, or --framed), or the built-in box with its own camera.
struct SceneEntry {
  std::string name, path;    // path empty: the built-in box
  std::optional<View> view;  // the camera and light, when the row is a view
};

// "cornell-original" -> "Original" (the study's names), "sponza" -> "Sponza".
std::string display_name(const std::string& view) {
  std::string n = view.rfind("cornell-", 0) == 0 ? view.substr(8) : view;
  if (!n.empty()) n[0] = char(std::toupper(static_cast<unsigned char>(n[0])));
  return n;
}

std::vector<SceneEntry> resolve_scenes(const BenchArgs& a) {
  const std::string views_path = a.views.empty() ? default_views_path() : a.views;
  std::optional<std::vector<View>> views;
  const auto all_views = [&]() -> const std::vector<View>& {
    if (!views) views = load_views(views_path);
    return *views;
  };
  std::vector<SceneEntry> out;
  const auto add_view = [&](const View& v) {
    out.push_back({display_name(v.name), v.obj, v});
    if (a.framed) out.push_back({display_name(v.name) + " (framed)", v.obj, std::nullopt});
  };
  for (const std::string& item : split_list("--scenes", a.scenes)) {
    const bool cornell = item == "cornell", large = item == "large", all = item == "all";
    if (cornell || large || all) {
      for (const View& v : all_views()) {
        const bool is_cornell = v.name.rfind("cornell-", 0) == 0;
        if (all || is_cornell == cornell) add_view(v);
      }
    } else if (item == "builtin") {
      out.push_back({"builtin", "", std::nullopt});
    } else if (item.find('/') == std::string::npos && item.find('.') == std::string::npos) {
      add_view(find_view(all_views(), item, views_path, "--scenes"));
    } else {
      std::string name = std::filesystem::path(item).stem().string();
      if (name.rfind("CornellBox-", 0) == 0) name = name.substr(11);  // the study's scene names
      out.push_back({name + " (framed)", item, std::nullopt});
    }
  }
  if (out.empty()) throw UsageError("--scenes: no scenes named");
  return out;
}

std::vector<Variant> resolve_variants(const std::string& spec) {
  std::vector<Variant> out;
  for (const std::string& item : split_list("--variants", spec)) {
    bool found = false;
    for (const Variant& v : all_variants()) {
      const bool group = item == "all" || (item == "study" && v.study) || (item == "ours" && !v.study);
      if (group || v.name == item) {
        if (v.accel == AccelKind::Embree && !embree_available()) {
          if (item == v.name) throw UsageError("--variants: 'embree' needs a build with Embree");
          continue;
        }
        out.push_back(v);
        found = true;
      }
    }
    if (!found) throw UsageError("--variants: unknown variant '" + item + "' (see tracer bench --list)");
  }
  if (out.empty()) throw UsageError("--variants: no variant left to run (Embree is not in this build)");
  return out;
}

struct Cell {
  std::string scene, variant;
  bool timed_out = false;
  double load_ms = 0, build_ms = 0, render_ms = 0, total_ms = 0;  // k-best means
  uint64_t rays = 0;
  double mrays = 0;
  size_t triangles = 0;
  std::vector<double> run_ms;
  bool capped(int runs) const { return !timed_out && int(run_ms.size()) < runs; }
};

std::string duration_text(double seconds) {
  char b[64];
  if (seconds < 120)
    std::snprintf(b, sizeof b, "%.0f s", seconds);
  else
    std::snprintf(b, sizeof b, "%.1f min", seconds / 60.0);
  return b;
}

double kbest_mean(std::vector<double> v, int best) {
  std::sort(v.begin(), v.end());
  const size_t k = std::min<size_t>(size_t(best), v.size());
  return k ? std::accumulate(v.begin(), v.begin() + long(k), 0.0) / double(k) : 0.0;
}

std::string fmt(double v, int prec = 1) {
  char b[64];
  std::snprintf(b, sizeof b, "%.*f", prec, v);
  return b;
}

// Stops a render after `seconds` through the scheduler's cancel flag.
class Watchdog {
 public:
  Watchdog(std::atomic<bool>& flag, double seconds) : flag_(flag) {
    thread_ = std::thread([this, seconds] {
      std::unique_lock lock(m_);
      if (!cv_.wait_for(lock, std::chrono::duration<double>(seconds), [this] { return done_; })) flag_ = true;
    });
  }
  ~Watchdog() {
    {
      std::lock_guard lock(m_);
      done_ = true;
    }
    cv_.notify_all();
    thread_.join();
  }

 private:
  std::atomic<bool>& flag_;
  std::mutex m_;
  std::condition_variable cv_;
  bool done_ = false;
  std::thread thread_;
};

std::string svg_chart(const std::vector<SceneEntry>& scenes, const std::vector<Variant>& variants,
                      const std::map<std::pair<std::string, std::string>, Cell>& cells) {
  // Grouped bars, log scale of total milliseconds; one group per scene, one colour per variant.
  const int bar = 10, gap = 24, left = 70, top = 30, height = 300;
  const int group = int(variants.size()) * bar + gap;
  const int width = left + int(scenes.size()) * group + 260;
  double lo = 1e30, hi = 0;
  for (const auto& [k, c] : cells) {
    if (c.timed_out || c.total_ms <= 0) continue;
    lo = std::min(lo, c.total_ms);
    hi = std::max(hi, c.total_ms);
  }
  if (hi <= 0) return "";
  const double l0 = std::floor(std::log10(lo)), l1 = std::ceil(std::log10(hi)) + (lo == hi ? 1 : 0);
  const auto y_of = [&](double ms) { return top + height - int((std::log10(ms) - l0) / (l1 - l0) * height); };
  std::ostringstream s;
  s << "<svg xmlns='http://www.w3.org/2000/svg' width='" << width << "' height='" << top + height + 60
    << "' font-family='sans-serif' font-size='11'>\n<rect width='100%' height='100%' fill='white'/>\n";
  for (double e = l0; e <= l1; e += 1) {
    const int y = y_of(std::pow(10.0, e));
    s << "<line x1='" << left << "' x2='" << left + int(scenes.size()) * group << "' y1='" << y << "' y2='" << y
      << "' stroke='#ddd'/>"
      << "<text x='" << left - 6 << "' y='" << y + 4 << "' text-anchor='end'>" << fmt(std::pow(10.0, e), 0)
      << " ms</text>\n";
  }
  for (size_t si = 0; si < scenes.size(); ++si) {
    const int gx = left + int(si) * group + gap / 2;
    for (size_t vi = 0; vi < variants.size(); ++vi) {
      const auto it = cells.find({scenes[si].name, variants[vi].name});
      if (it == cells.end() || it->second.timed_out || it->second.total_ms <= 0) continue;
      const int y = y_of(it->second.total_ms);
      s << "<rect x='" << gx + int(vi) * bar << "' y='" << y << "' width='" << bar - 1 << "' height='"
        << top + height - y << "' fill='hsl(" << (vi * 360 / variants.size()) << ",60%,50%)'><title>"
        << variants[vi].name << " on " << scenes[si].name << ": " << fmt(it->second.total_ms) << " ms</title></rect>\n";
    }
    s << "<text x='" << gx + int(variants.size()) * bar / 2 << "' y='" << top + height + 16 << "' text-anchor='middle'>"
      << scenes[si].name << "</text>\n";
  }
  for (size_t vi = 0; vi < variants.size(); ++vi) {
    const int x = left + int(scenes.size()) * group + 20, y = top + int(vi) * 16;
    s << "<rect x='" << x << "' y='" << y << "' width='10' height='10' fill='hsl(" << (vi * 360 / variants.size())
      << ",60%,50%)'/>"
      << "<text x='" << x + 16 << "' y='" << y + 9 << "'>" << variants[vi].name << "</text>\n";
  }
  s << "<text x='" << left
    << "' y='16' font-size='13'>tracer bench: build + render time per scene and variant (log scale, k-best "
       "mean)</text>\n</svg>\n";
  return s.str();
}

}  // namespace

void add_bench_options(CLI::App& app, BenchArgs& a) {
  app.add_option("--variants", a.variants, "variants: names, or study, ours, all")->capture_default_str();
  app.add_option(
         "--scenes", a.scenes,
         "scenes: view names from --views, or cornell, large, all (views); builtin; OBJ paths (framed from outside)")
      ->capture_default_str();
  app.add_option("--views", a.views,
                 "views file: name, OBJ, camera and light per line (default ../shared/scenes/views.tsv)");
  app.add_flag("--framed", a.framed, "also time each view's scene framed from outside its bounds, as a labelled row");
  app.add_option("--size", a.size, "image size WxH")->capture_default_str();
  app.add_option("--ao", a.ao, "AO rays per hit")->capture_default_str();
  app.add_option("--integrator", a.integrator,
                 "workload: " + names_of<Integrator>(kIntegratorNames) + " (ao: the study's; path: incoherent rays)")
      ->capture_default_str();
  app.add_option("--spp", a.spp, "path: samples per pixel (1-65536)")->capture_default_str();
  app.add_option("--runs", a.runs, "timed runs per cell")->capture_default_str();
  app.add_option("--best", a.best, "mean of the best k runs (the study's k-best rule)")->capture_default_str();
  app.add_option("--threads", a.threads, "threads for the parallel variants (default: all)");
  app.add_option("--max-seconds", a.max_seconds,
                 "time cap per cell, all its runs together: later runs are skipped, a run at the cap is stopped")
      ->capture_default_str();
  app.add_option("--json", a.json, "write raw figures as JSON");
  app.add_option("--plot", a.plot, "write a grouped bar chart (SVG, log scale)");
  app.add_option("--markdown", a.markdown, "also write the tables to this Markdown file");
  app.add_flag("--list", a.list, "list the variants and exit");
}

int run_bench(const BenchArgs& a) {
  if (a.list) {
    for (const Variant& v : all_variants())
      std::printf("%-24s %s%s\n", v.name.c_str(), v.description.c_str(), v.study ? " (study)" : "");
    return 0;
  }
  const auto [width, height] = parse_size("--size", a.size);
  check_range("--ao", a.ao, 0, 4096);
  check_range("--spp", a.spp, 1, 65536);
  const Integrator integrator = parse_name<Integrator>(kIntegratorNames, a.integrator, "--integrator", "integrator");
  check_range("--runs", a.runs, 1, 1000);
  check_range("--best", a.best, 1, a.runs);
  if (a.threads) check_range("--threads", *a.threads, 1, 1024);
  const int threads = a.threads.value_or(0);
  const ThreadLimit thread_limit(threads);
  check_range_real("--max-seconds", a.max_seconds, 0.0, 1e7, true);
  const std::vector<Variant> variants = resolve_variants(a.variants);
  const std::vector<SceneEntry> scenes = resolve_scenes(a);
  const std::pair<const std::string*, const char*> outputs[] = {
      {&a.json, "--json"}, {&a.plot, "--plot"}, {&a.markdown, "--markdown"}};
  // Up front against the scene files (loaded later, one at a time) and the views file (read).
  for (const auto& [out, flag] : outputs) {
    if (out->empty()) continue;
    check_output(*out, flag);
    for (const SceneEntry& se : scenes) {
      if (!se.path.empty() && same_file(*out, se.path)) {
        throw UsageError(std::string(flag) + ": '" + *out + "' is an input of this run (" + se.path + ")");
      }
    }
  }

  std::map<std::pair<std::string, std::string>, Cell> cells;
  const size_t total_cells = variants.size() * scenes.size();
  size_t done_cells = 0;
  const auto bench_start = Clock::now();
  const bool tty = ::isatty(STDERR_FILENO);
  std::fprintf(
      stderr,
      "tracer bench: %zu cells (%zu scenes x %zu variants), up to %d runs each, at most %s s per cell: at most %s\n",
      total_cells, scenes.size(), variants.size(), a.runs, fmt(a.max_seconds, 0).c_str(),
      duration_text(double(total_cells) * a.max_seconds).c_str());
  for (const SceneEntry& se : scenes) {
    const auto t_load = Clock::now();
    Scene scene = se.path.empty() ? make_cornell_box(0) : load_obj(se.path, [](const std::string&) {});
    if (se.view) apply_view_light(scene, *se.view);
    const double load_ms = std::chrono::duration<double, std::milli>(Clock::now() - t_load).count();
    const CameraSpec cam = se.view ? se.view->camera : scene.camera ? *scene.camera : frame_bounds(scene.bounds);
    for (const Variant& v : variants) {
      Cell cell;
      cell.scene = se.name;
      cell.variant = v.name;
      cell.triangles = scene.size();
      cell.load_ms = load_ms;
      std::vector<double> builds, renders;
      const auto cell_start = Clock::now();
      for (int run = 0; run < a.runs && !cell.timed_out; ++run) {
        // The cap bounds the whole cell: later runs are skipped once it is spent, and a run still
        // going at the cap is stopped (the cell times out only if no run finished).
        const double left = a.max_seconds - std::chrono::duration<double>(Clock::now() - cell_start).count();
        if (run > 0 && left <= 0) break;
        if (tty || run == 0) {  // logs get one line per cell
          const double elapsed = std::chrono::duration<double>(Clock::now() - bench_start).count();
          const double frac = (double(done_cells) + double(run) / a.runs) / double(total_cells);
          std::fprintf(stderr, "%scell %zu/%zu %-10s %-24s run %2d/%d  elapsed %6.0fs  ETA %s%s", tty ? "\r" : "",
                       done_cells + 1, total_cells, se.name.c_str(), v.name.c_str(), run + 1, a.runs, elapsed,
                       frac > 0 ? (fmt(elapsed * (1 - frac) / frac, 0) + "s").c_str() : "?", tty ? "   " : "\n");
        }
        AccelOptions ao;
        ao.kind = v.accel;
        ao.bvh.split = v.split;
        ao.bvh.mode = v.build;
        ao.bvh.threads = threads;
        const Accelerator accel = build_accelerator(scene, ao);
        RenderSettings rs;
        rs.width = width;
        rs.height = height;
        rs.ao_samples = a.ao;
        rs.integrator = integrator;
        rs.spp = integrator == Integrator::Path ? a.spp : 1;
        rs.packets = v.packets && integrator == Integrator::Ao;
        Framebuffer fb(width, height);
        RenderContext ctx{&scene, Camera(cam, width, height), rs, &fb};
        ctx.samples = {0, uint32_t(rs.spp)};  // one pass: the timing has no pass overhead
        std::atomic<bool> stop{false};
        RenderControl control;
        control.cancel = &stop;
        SchedOptions so;
        so.kind = v.sched;
        so.threads = threads;
        const auto t0 = Clock::now();
        bool finished;
        {
          Watchdog watchdog(stop, std::max(0.0, left - accel.build_ms / 1000.0));
          finished = render_image(accel, ctx, so, control);
        }
        const double render_ms = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
        if (!finished) {
          cell.timed_out = run == 0;
          break;
        }
        builds.push_back(accel.build_ms);
        renders.push_back(render_ms);
        cell.run_ms.push_back(accel.build_ms + render_ms);
        cell.rays = control.counts.load().total();
      }
      if (!cell.timed_out) {
        cell.build_ms = kbest_mean(builds, a.best);
        cell.render_ms = kbest_mean(renders, a.best);
        cell.total_ms = kbest_mean(cell.run_ms, a.best);
        cell.mrays = cell.render_ms > 0 ? double(cell.rays) / (cell.render_ms * 1e3) : 0;
      }
      cells[{se.name, v.name}] = cell;
      ++done_cells;
    }
  }
  if (tty) std::fprintf(stderr, "\r%100s\r", "");

  // Tables.
  std::ostringstream md;
  const auto header = [&](const std::string& title) {
    md << "\n### " << title << "\n\n| scene | triangles |";
    for (const Variant& v : variants) md << " " << v.name << " |";
    md << "\n|---|---:|";
    for (size_t i = 0; i < variants.size(); ++i) md << "---:|";
    md << "\n";
  };
  const auto row = [&](const auto& value_of) {
    for (const SceneEntry& se : scenes) {
      md << "| " << se.name << " | " << cells[{se.name, variants[0].name}].triangles << " |";
      for (const Variant& v : variants) md << " " << value_of(se, v, cells[{se.name, v.name}]) << " |";
      md << "\n";
    }
  };
  const std::string timeout_text = "> " + fmt(a.max_seconds, 0) + " s";
  const std::string workload = integrator == Integrator::Ao        ? std::to_string(a.ao) + " AO rays per hit"
                               : integrator == Integrator::Whitted ? std::string("whitted")
                                                                   : "path, " + std::to_string(a.spp) + " spp";
  md << "tracer bench: " << width << "x" << height << ", " << workload << ", " << a.runs << " runs, mean of best "
     << a.best << ", threads " << resolve_thread_count(threads) << "\n";
  header("Build + render time, ms (k-best mean)");
  row([&](const SceneEntry&, const Variant&, const Cell& c) {
    return c.timed_out ? timeout_text : fmt(c.total_ms) + (c.capped(a.runs) ? "*" : "");
  });
  if (std::any_of(cells.begin(), cells.end(), [&](const auto& kv) { return kv.second.capped(a.runs); })) {
    md << "\n\\* fewer than " << a.runs << " runs: the cell reached the " << fmt(a.max_seconds, 0)
       << " s cap (--max-seconds); the mean is over the best of the runs it made.\n";
  }
  header("Build time, ms");
  row([&](const SceneEntry&, const Variant&, const Cell& c) {
    return c.timed_out ? std::string("-") : fmt(c.build_ms, 2);
  });
  header("Throughput, Mrays/s (render only)");
  row([&](const SceneEntry&, const Variant&, const Cell& c) {
    return c.timed_out ? std::string("-") : fmt(c.mrays, 2);
  });
  const bool have_seq = std::any_of(variants.begin(), variants.end(), [](const Variant& v) { return v.name == "seq"; });
  if (have_seq) {
    header("Speedup over seq (same scene, same run)");
    row([&](const SceneEntry& se, const Variant&, const Cell& c) {
      const Cell& s = cells[{se.name, "seq"}];
      if (c.timed_out || s.timed_out) return std::string("-");
      return fmt(s.total_ms / c.total_ms, 2) + "x";
    });
    header("Study comparison: speedup over seq, ours / study's");
    row([&](const SceneEntry& se, const Variant& v, const Cell& c) {
      const auto sit = study_ms().find(se.name.substr(0, se.name.find(" (framed)")));
      const Cell& s = cells[{se.name, "seq"}];
      if (sit == study_ms().end() || !sit->second.count(v.name) || c.timed_out || s.timed_out) return std::string("-");
      const double study_speedup = sit->second.at("seq") / sit->second.at(v.name);
      return fmt(s.total_ms / c.total_ms, 1) + " / " + fmt(study_speedup, 1);
    });
  }
  for (const auto& [reference_name, title] : {std::pair<std::string, std::string>{"embree", "Embree's single rays"},
                                              {"embree-packets", "Embree's packet API"}}) {
    // A plain reference: clang 14 cannot capture a structured binding in a lambda.
    const std::string& reference = reference_name;
    const bool present =
        std::any_of(variants.begin(), variants.end(), [&](const Variant& v) { return v.name == reference; });
    if (!present) continue;
    header("Throughput relative to " + title + " (Mrays/s ratio, same rays, same run)");
    row([&](const SceneEntry& se, const Variant&, const Cell& c) {
      const Cell& e = cells[{se.name, reference}];
      if (c.timed_out || e.timed_out || e.mrays <= 0) return std::string("-");
      return fmt(c.mrays / e.mrays, 2) + "x";
    });
  }
  std::cout << md.str();
  // Every output once more against every file the run read (MTL files, textures), before any
  // of them is written.
  for (const auto& [out, flag] : outputs) {
    if (!out->empty()) check_output(*out, flag);
  }
  if (!a.markdown.empty()) write_file_atomic(a.markdown, md.str());
  if (!a.json.empty()) {
    nlohmann::json j = {{"size", {width, height}},
                        {"ao", a.ao},
                        {"runs", a.runs},
                        {"best", a.best},
                        {"cells", nlohmann::json::array()}};
    for (const auto& [key, c] : cells) {
      j["cells"].push_back({{"scene", c.scene},
                            {"variant", c.variant},
                            {"triangles", c.triangles},
                            {"timed_out", c.timed_out},
                            {"load_ms", c.load_ms},
                            {"build_ms", c.build_ms},
                            {"render_ms", c.render_ms},
                            {"total_ms", c.total_ms},
                            {"rays", c.rays},
                            {"mrays_per_s", c.mrays},
                            {"runs_ms", c.run_ms}});
    }
    write_file_atomic(a.json, j.dump(2) + "\n");
  }
  if (!a.plot.empty()) write_file_atomic(a.plot, svg_chart(scenes, variants, cells));
  return 0;
}

}  // namespace tracer::cli
