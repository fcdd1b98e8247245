// Writes a scene placed N times on a square grid as glTF (tinygltf's writer), for the instancing
// benchmarks (scripts/benchmarks-instances.sh): every geometry of SCENE placed by N nodes, each
// turned about y by its own angle; --distinct gives each placement its own mesh (the same
// accessors), a file tracer loads flat: the instanced scene's triangles, flattened.
//   tracer_make_instances SCENE N OUT.gltf [--distinct]
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "importers/scene_file.hpp"
#include "scene_writers.hpp"

int main(int argc, char** argv) {
  using namespace tracer;
  if (argc < 4) {
    std::fprintf(stderr, "usage: tracer_make_instances SCENE N OUT.gltf [--distinct]\n");
    return 2;
  }
  const Scene scene = load_scene_file(argv[1]);
  const long n = std::strtol(argv[2], nullptr, 10);
  if (n < 1) {
    std::fprintf(stderr, "tracer_make_instances: N must be at least 1\n");
    return 2;
  }
  const Vec3 e = scene.bounds.extent();
  const double step = 1.1 * double(std::max(e.x, e.z));
  const auto side = long(std::ceil(std::sqrt(double(n))));
  test::GltfWriteOptions options;
  options.distinct_meshes = argc > 4 && std::string(argv[4]) == "--distinct";
  std::vector<std::array<double, 16>> placements;
  for (long k = 0; k < n; ++k) {
    const double a = 0.37 * double(k % side + 3 * (k / side)), c = std::cos(a), s = std::sin(a);
    placements.push_back(
        {c, 0, -s, 0, 0, 1, 0, 0, s, 0, c, 0, double(k % side) * step, 0, -double(k / side) * step, 1});
  }
  for (uint32_t g = 0; g < scene.geometries.size(); ++g) options.placements[g] = placements;
  test::write_gltf(scene, argv[3], options);
  std::printf("%s: %zu triangles placed %ld times (%.4g), grid step %g\n", argv[3], scene.size(), n,
              double(scene.size()) * double(n), step);
  return 0;
}
