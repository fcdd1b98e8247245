// Load time of one scene in each format tracer reads: an OBJ file, and the same geometry written
// (tests/scene_writers.hpp) as .gltf + .bin, .glb, binary and ASCII PLY. Each is loaded by
// tracer's importer; the .glb and the binary PLY also by assimp (5.2.5, Debian's), the library
// issue #41 offered for both, when the build found it. Prints one JSON object; each time is the
// best of --runs runs, files in the page cache, geometry only (no textures are read, none are
// written). The files stay in --keep DIR when given.
//   build/release/bench/tracer_format_load FILE.obj [--runs N] [--threads N] [--keep DIR]
#include <malloc.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#ifdef TRACER_HAVE_ASSIMP
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <assimp/Importer.hpp>
#endif

#include "importers/obj_loader.hpp"
#include "importers/scene_file.hpp"
#include "parallel/executor.hpp"
#include "scene_writers.hpp"

namespace {

namespace fs = std::filesystem;

double best_ms(int runs, const std::function<void()>& f) {
  f();  // once unmeasured: page faults of the first allocation of this size
  double best = 1e300;
  for (int r = 0; r < runs; ++r) {
    const auto t0 = std::chrono::steady_clock::now();
    f();
    best = std::min(best, std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
  }
  return best;
}

}  // namespace

int main(int argc, char** argv) {
  std::string path, keep;
  int runs = 3, threads = 1;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if ((a == "--runs" || a == "--threads") && i + 1 < argc) {
      (a == "--runs" ? runs : threads) = std::max(1, std::atoi(argv[++i]));
    } else if (a == "--keep" && i + 1 < argc) {
      keep = argv[++i];
    } else if (path.empty() && a.rfind("--", 0) != 0) {
      path = a;
    } else {
      path.clear();
      break;
    }
  }
  if (path.empty()) {
    std::fprintf(stderr, "usage: %s FILE.obj [--runs N] [--threads N] [--keep DIR]\n", argv[0]);
    return 2;
  }
  mallopt(M_MMAP_THRESHOLD, 1 << 30);  // as bench/load_time.cpp: compare parsing, not page faults
  mallopt(M_TRIM_THRESHOLD, 1 << 30);
  const tracer::Executor executor(tracer::Strategy::Tbb, threads);
  tracer::LoadLimits limits;
  limits.read_textures = false;
  limits.for_each = [&executor](size_t count, const std::function<void(size_t)>& body) {
    executor.for_each(count, body);
  };
  const auto quiet = [](const std::string&) {};
  const tracer::Scene scene = tracer::load_obj(path, quiet, nullptr, limits);
  const fs::path dir =
      keep.empty() ? fs::temp_directory_path() / ("tracer-formats-" + std::to_string(getpid())) : fs::path(keep);
  fs::create_directories(dir);
  const std::string stem = (dir / fs::path(path).stem()).string();
  tracer::test::write_gltf(scene, stem + ".gltf");
  tracer::test::write_gltf(scene, stem + ".glb", {.binary = true});
  tracer::test::write_ply(scene, stem + "-binary.ply", tracer::test::PlyEncoding::BinaryLittle);
  tracer::test::write_ply(scene, stem + "-ascii.ply", tracer::test::PlyEncoding::Ascii);
  size_t triangles = 0;
  const auto tracer_load = [&](const std::string& file) {
    return best_ms(
        runs, [&] { executor.run([&] { triangles = tracer::load_scene_file(file, quiet, nullptr, limits).size(); }); });
  };
  const double obj = tracer_load(path), gltf = tracer_load(stem + ".gltf"), glb = tracer_load(stem + ".glb"),
               ply = tracer_load(stem + "-binary.ply"), ply_ascii = tracer_load(stem + "-ascii.ply");
  std::printf(
      "{\"file\": \"%s\", \"triangles\": %zu, \"runs\": %d, \"threads\": %d, \"obj_ms\": %.1f, "
      "\"gltf_ms\": %.1f, \"glb_ms\": %.1f, \"ply_binary_ms\": %.1f, \"ply_ascii_ms\": %.1f",
      path.c_str(), triangles, runs, threads, obj, gltf, glb, ply, ply_ascii);
#ifdef TRACER_HAVE_ASSIMP
  const auto assimp_load = [&](const std::string& file) {
    return best_ms(runs, [&] {
      Assimp::Importer importer;
      const aiScene* s = importer.ReadFile(file, aiProcess_Triangulate);
      if (!s) {
        std::fprintf(stderr, "assimp: %s: %s\n", file.c_str(), importer.GetErrorString());
        std::exit(1);
      }
    });
  };
  std::printf(", \"assimp_glb_ms\": %.1f, \"assimp_ply_binary_ms\": %.1f", assimp_load(stem + ".glb"),
              assimp_load(stem + "-binary.ply"));
#endif
  std::printf("}\n");
  if (keep.empty()) fs::remove_all(dir);
  return 0;
}
