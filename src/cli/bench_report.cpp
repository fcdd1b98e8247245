#include "cli/bench_report.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "parallel/thread_count.hpp"

namespace tracer::cli {

std::string fmt(double v, int prec) {
  char b[64];
  std::snprintf(b, sizeof b, "%.*f", prec, v);
  return b;
}

std::string duration_text(double seconds) {
  char b[64];
  if (seconds < 120)
    std::snprintf(b, sizeof b, "%.0f s", seconds);
  else
    std::snprintf(b, sizeof b, "%.1f min", seconds / 60.0);
  return b;
}

std::string markdown_tables(const BenchReport& r) {
  const BenchArgs& a = r.args;
  const std::vector<SceneEntry>& scenes = r.scenes;
  const std::vector<Variant>& variants = r.variants;
  CellTable cells = r.cells;  // operator[] below
  const int width = r.width, height = r.height, threads = r.threads;
  const Integrator integrator = r.integrator;
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
      for (const Variant& v : variants) {
        const Cell& c = cells[{se.name, v.name}];
        md << " " << (c.not_traced ? std::string("n/a") : value_of(se, v, c)) << " |";
      }
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
      if (c.timed_out || s.timed_out || s.not_traced) return std::string("-");
      return fmt(s.total_ms / c.total_ms, 2) + "x";
    });
    header("Study comparison: speedup over seq, ours / study's");
    row([&](const SceneEntry& se, const Variant& v, const Cell& c) {
      const auto sit = study_ms().find(se.name.substr(0, se.name.find(" (framed)")));
      const Cell& s = cells[{se.name, "seq"}];
      if (sit == study_ms().end() || !sit->second.count(v.name) || c.timed_out || s.timed_out || s.not_traced)
        return std::string("-");
      const double study_speedup = sit->second.at("seq") / sit->second.at(v.name);
      return fmt(s.total_ms / c.total_ms, 1) + " / " + fmt(study_speedup, 1);
    });
  }
  for (const auto& [reference_name, title] : {std::pair<std::string, std::string>{"embree", "Embree's single rays"},
                                              {"embree-packets", "Embree's packet API"},
                                              {"embree-streams", "Embree's stream API on the same sorted AO rays"},
                                              {"embree-high", "Embree's single rays at HIGH build quality"},
                                              {"embree-high-packets", "Embree's packet API at HIGH build quality"}}) {
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
  return md.str();
}

std::string json_report(const BenchReport& r) {
  const BenchArgs& a = r.args;
  const int width = r.width, height = r.height;
  const CellTable& cells = r.cells;
  nlohmann::json j = {
      {"size", {width, height}}, {"ao", a.ao}, {"runs", a.runs}, {"best", a.best}, {"cells", nlohmann::json::array()}};
  for (const auto& [key, c] : cells) {
    j["cells"].push_back({{"scene", c.scene},
                          {"variant", c.variant},
                          {"triangles", c.triangles},
                          {"timed_out", c.timed_out},
                          {"not_traced", c.not_traced},
                          {"load_ms", c.load_ms},
                          {"build_ms", c.build_ms},
                          {"render_ms", c.render_ms},
                          {"total_ms", c.total_ms},
                          {"rays", c.rays},
                          {"mrays_per_s", c.mrays},
                          {"runs_ms", c.run_ms}});
  }
  return j.dump(2) + "\n";
}

std::string svg_chart(const BenchReport& r) {
  const std::vector<SceneEntry>& scenes = r.scenes;
  const std::vector<Variant>& variants = r.variants;
  const CellTable& cells = r.cells;
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

}  // namespace tracer::cli
