#include "cli/bench_catalogue.hpp"

#include <cctype>
#include <filesystem>

#include "base/errors.hpp"
#include "frontend/parse.hpp"

namespace tracer::cli {

using namespace frontend;

const std::vector<Variant>& all_variants() {
  static const std::vector<Variant> v = {
      {"seq", AccelKind::Brute, BvhSplit::Median, Strategy::Seq, Strategy::Seq, "brute force, one thread", true},
      {"async", AccelKind::Brute, BvhSplit::Median, Strategy::Seq, Strategy::Async, "brute force, std::async per row",
       true},
      {"bvh", AccelKind::Bvh, BvhSplit::Median, Strategy::Seq, Strategy::Seq, "median BVH, one thread", true},
      {"async+bvh", AccelKind::Bvh, BvhSplit::Median, Strategy::Seq, Strategy::Async, "median BVH, async rows", true},
      {"async+bvh+parbuild-v1", AccelKind::Bvh, BvhSplit::Median, Strategy::Async, Strategy::Async,
       "median BVH built with std::async, async rows", true},
      {"lq+bvh+parbuild-v1", AccelKind::Bvh, BvhSplit::Median, Strategy::Async, Strategy::Queue,
       "median BVH built with std::async, locked queue", true},
      {"async+bvh+parbuild-v2", AccelKind::Bvh, BvhSplit::Median, Strategy::Queue, Strategy::Async,
       "median BVH built by a job queue, async rows", true},
      {"lq+bvh+parbuild-v2", AccelKind::Bvh, BvhSplit::Median, Strategy::Queue, Strategy::Queue,
       "median BVH built by a job queue, locked queue", true},
      {"lq", AccelKind::Brute, BvhSplit::Median, Strategy::Seq, Strategy::Queue, "brute force, locked queue", true},
      {"simd-brute", AccelKind::BruteSimd, BvhSplit::Median, Strategy::Seq, Strategy::Seq,
       "brute force, 8 triangles per SIMD test, one thread (the study's ISPC)", true},
      {"sah", AccelKind::Bvh, BvhSplit::Sah, Strategy::Seq, Strategy::Seq, "SAH BVH, one thread", false},
      {"async+sah", AccelKind::Bvh, BvhSplit::Sah, Strategy::Tbb, Strategy::Async,
       "SAH BVH (TBB build), std::async per row", false},
      {"lq+sah", AccelKind::Bvh, BvhSplit::Sah, Strategy::Tbb, Strategy::Queue,
       "SAH BVH (TBB build), locked queue of 64-pixel blocks", false},
      {"atomic+sah", AccelKind::Bvh, BvhSplit::Sah, Strategy::Tbb, Strategy::Atomic,
       "SAH BVH (TBB build), atomic tile counter", false},
      {"tbb+sah", AccelKind::Bvh, BvhSplit::Sah, Strategy::Tbb, Strategy::Tbb, "SAH BVH (TBB build), TBB work stealing",
       false},
      {"bvh8", AccelKind::Bvh8, BvhSplit::Sah, Strategy::Tbb, Strategy::Tbb,
       "8-wide SIMD BVH (TBB build), TBB work stealing", false},
      {"best", AccelKind::Bvh8, BvhSplit::Sah, Strategy::Tbb, Strategy::Tbb,
       "8-wide SIMD BVH (TBB build), primary-ray packets and AO bundles, TBB work stealing", false, true},
      {"best-streams", AccelKind::Bvh8, BvhSplit::Sah, Strategy::Tbb, Strategy::Tbb,
       "8-wide SIMD BVH (TBB build), primary-ray packets, AO rays in sorted streams per 16x16 pixels, TBB work "
       "stealing",
       false, true, BuildQuality::Medium, true},
      {"bvh8-high", AccelKind::Bvh8, BvhSplit::Sah, Strategy::Tbb, Strategy::Tbb,
       "8-wide SIMD BVH at high build quality (spatial splits), TBB work stealing", false, false, BuildQuality::High},
      {"best-high", AccelKind::Bvh8, BvhSplit::Sah, Strategy::Tbb, Strategy::Tbb,
       "8-wide SIMD BVH at high build quality, primary-ray packets and AO bundles, TBB work stealing", false, true,
       BuildQuality::High},
      {"embree", AccelKind::Embree, BvhSplit::Sah, Strategy::Tbb, Strategy::Tbb,
       "Intel Embree 3, single rays (rtcIntersect1/rtcOccluded1), TBB work stealing", false},
      {"embree-packets", AccelKind::Embree, BvhSplit::Sah, Strategy::Tbb, Strategy::Tbb,
       "Intel Embree 3, packets: rtcIntersect16 per 4x4 block, rtcOccluded16 for its shadow rays and for each hit's "
       "AO rays, TBB work stealing",
       false, true},
      {"embree-streams", AccelKind::Embree, BvhSplit::Sah, Strategy::Tbb, Strategy::Tbb,
       "Intel Embree 3, packets as embree-packets, but AO rays as the same sorted streams best-streams traces, by "
       "rtcOccluded1M (coherent), TBB work stealing",
       false, true, BuildQuality::Medium, true},
      {"embree-high", AccelKind::EmbreeHigh, BvhSplit::Sah, Strategy::Tbb, Strategy::Tbb,
       "Intel Embree 3 at its HIGH build quality (spatial splits), single rays, TBB work stealing", false},
      {"embree-high-packets", AccelKind::EmbreeHigh, BvhSplit::Sah, Strategy::Tbb, Strategy::Tbb,
       "Intel Embree 3 at its HIGH build quality, packets as embree-packets, TBB work stealing", false, true},
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

namespace {

// "cornell-original" -> "Original" (the study's names), "sponza" -> "Sponza".
std::string display_name(const std::string& view) {
  std::string n = view.rfind("cornell-", 0) == 0 ? view.substr(8) : view;
  if (!n.empty()) n[0] = char(std::toupper(static_cast<unsigned char>(n[0])));
  return n;
}

}  // namespace

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
    } else if (item == "instanced") {
      const View& bunny = find_view(all_views(), "bunny", views_path, "--scenes instanced");
      out.push_back({display_name(bunny.name) + " x" + std::to_string(kInstancedPlacements) + " (instanced)", bunny.obj,
                     std::nullopt, kInstancedPlacements});
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
        if (is_embree(v.accel) && !embree_available()) {
          if (item == v.name) throw UsageError("--variants: '" + v.name + "' needs a build with Embree");
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

}  // namespace tracer::cli
