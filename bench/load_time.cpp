// Load time of an OBJ file, tracer's loader against tinyobjloader's own parse of the same file
// (LoadObj from the path, triangulating, materials read): the "loading" row of the scaling
// benchmark (scripts/benchmarks-scale.sh). Prints one JSON object; each time is the median of
// --runs runs, the file already in the page cache.
//   build/release/bench/tracer_load_time FILE.obj [--runs N]
#include <tiny_obj_loader.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "scene/obj_loader.hpp"

namespace {

template <class F>
double median_ms(int runs, F&& f) {
  std::vector<double> ms;
  for (int i = 0; i < runs; ++i) {
    const auto t0 = std::chrono::steady_clock::now();
    f();
    ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
  }
  std::sort(ms.begin(), ms.end());
  return ms[ms.size() / 2];
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2 && !(argc == 4 && std::string(argv[2]) == "--runs")) {
    std::fprintf(stderr, "usage: %s FILE.obj [--runs N]\n", argv[0]);
    return 2;
  }
  const std::string path = argv[1];
  const int runs = argc == 4 ? std::max(1, std::atoi(argv[3])) : 3;
  size_t triangles = 0;
  const double tracer_ms =
      median_ms(runs, [&] { triangles = tracer::load_obj(path, [](const std::string&) {}).size(); });
  const std::string dir = std::filesystem::path(path).parent_path().string();
  const double tinyobj_ms = median_ms(runs, [&] {
    tinyobj::attrib_t attrib;
    std::vector<tinyobj::shape_t> shapes;
    std::vector<tinyobj::material_t> materials;
    std::string warn, err;
    if (!tinyobj::LoadObj(&attrib, &shapes, &materials, &warn, &err, path.c_str(), dir.empty() ? nullptr : dir.c_str(),
                          /*triangulate=*/true)) {
      std::fprintf(stderr, "tinyobjloader: %s\n", err.c_str());
      std::exit(1);
    }
  });
  std::printf("{\"file\": \"%s\", \"triangles\": %zu, \"runs\": %d, \"tracer_ms\": %.1f, \"tinyobjloader_ms\": %.1f}\n",
              path.c_str(), triangles, runs, tracer_ms, tinyobj_ms);
  return 0;
}
