// Load time of an OBJ file, tracer's loader against tinyobjloader's own parse of the same file
// (LoadObj from the path, triangulating, materials read, on one thread: it has no other): the
// "loading" row of the scaling benchmark (scripts/benchmarks-scale.sh). Prints one JSON object;
// each time is the best of --runs runs, the file already in the page cache. tracer_ms is the
// whole load; geometry_ms the load without reading any texture (LoadLimits::read_textures), which is
// what tinyobjloader does.
// --once tracer|geometry|tinyobjloader loads once with that loader and prints nothing: what to
// count instructions of, with valgrind, where this VM's times are too noisy to compare.
//   build/release/bench/tracer_load_time FILE.obj [--runs N] [--threads N] [--once LOADER]
#include <tiny_obj_loader.h>

#include <malloc.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "importers/obj_loader.hpp"
#include "parallel/executor.hpp"

namespace {

template <class F>
double time_ms(F&& f) {
  const auto t0 = std::chrono::steady_clock::now();
  f();
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

// The best of the runs: this VM's noise only ever adds time.
double best(const std::vector<double>& ms) { return *std::min_element(ms.begin(), ms.end()); }

}  // namespace

int main(int argc, char** argv) {
  std::string path;
  int runs = 3, threads = 1;
  std::string once;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--once" && i + 1 < argc) {
      once = argv[++i];
    } else if ((a == "--runs" || a == "--threads") && i + 1 < argc) {
      (a == "--runs" ? runs : threads) = std::max(1, std::atoi(argv[++i]));
    } else if (path.empty() && a.rfind("--", 0) != 0) {
      path = a;
    } else {
      path.clear();
      break;
    }
  }
  if (path.empty()) {
    std::fprintf(stderr, "usage: %s FILE.obj [--runs N] [--threads N] [--once tracer|geometry|tinyobjloader]\n",
                 argv[0]);
    return 2;
  }
  // Freed memory stays in the process for the next run of either loader (glibc would otherwise
  // hand large blocks back and the next run fault them in again at ~7 us a page on this VM): the
  // runs then compare parsing, not the page faults of whichever allocated last. A fresh process
  // pays them (tracer render --stats shows its load's phases).
  mallopt(M_MMAP_THRESHOLD, 1 << 30);
  mallopt(M_TRIM_THRESHOLD, 1 << 30);
  const tracer::Executor executor(tracer::Strategy::Tbb, threads);
  tracer::LoadLimits limits;
  limits.max_obj_bytes = UINT64_MAX;  // the file is named on purpose, however large
  limits.for_each = [&executor](size_t count, const std::function<void(size_t)>& body) {
    executor.for_each(count, body);
  };
  size_t triangles = 0;
  const std::string dir = std::filesystem::path(path).parent_path().string();
  tracer::LoadLimits geometry_only = limits;
  geometry_only.read_textures = false;
  const auto load_tracer = [&](const tracer::LoadLimits& l) {
    executor.run([&] {
      triangles = tracer::load_obj(
                      path, [](const std::string&) {}, nullptr, l)
                      .size();
    });
  };
  const auto load_tinyobj = [&] {
    tinyobj::attrib_t attrib;
    std::vector<tinyobj::shape_t> shapes;
    std::vector<tinyobj::material_t> materials;
    std::string warn, err;
    if (!tinyobj::LoadObj(&attrib, &shapes, &materials, &warn, &err, path.c_str(), dir.empty() ? nullptr : dir.c_str(),
                          /*triangulate=*/true)) {
      std::fprintf(stderr, "tinyobjloader: %s\n", err.c_str());
      std::exit(1);
    }
  };
  if (!once.empty()) {
    if (once == "tracer" || once == "geometry") {
      load_tracer(once == "tracer" ? limits : geometry_only);
    } else if (once == "tinyobjloader") {
      load_tinyobj();
    } else {
      std::fprintf(stderr, "--once: 'tracer', 'geometry' or 'tinyobjloader', not '%s'\n", once.c_str());
      return 2;
    }
    return 0;
  }
  // One unmeasured load of each first, then they alternate: on a VM whose first touch of a page
  // costs ~10 us, whichever ran first would otherwise pay the process's page faults for all.
  load_tracer(limits);
  load_tinyobj();
  std::vector<double> whole, geometry, theirs;
  for (int r = 0; r < runs; ++r) {
    whole.push_back(time_ms([&] { load_tracer(limits); }));
    geometry.push_back(time_ms([&] { load_tracer(geometry_only); }));
    theirs.push_back(time_ms(load_tinyobj));
  }
  std::printf(
      "{\"file\": \"%s\", \"triangles\": %zu, \"runs\": %d, \"threads\": %d, \"tracer_ms\": %.1f, "
      "\"geometry_ms\": %.1f, \"tinyobjloader_ms\": %.1f}\n",
      path.c_str(), triangles, runs, threads, best(whole), best(geometry), best(theirs));
  return 0;
}
