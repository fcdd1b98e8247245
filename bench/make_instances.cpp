// Writes a scene placed N times on a square grid as glTF (tinygltf's writer), for the instancing
// benchmarks (scripts/benchmarks-instances.sh): every geometry of SCENE placed by N nodes on
// scene/builtin.hpp's grid (grid_placements), each turned about y by its own angle; --distinct gives each placement its
// own mesh (the same accessors), a file tracer loads flat: the instanced scene's triangles, flattened.
// --one-mesh writes SCENE's geometries as the primitives of one mesh (as an exporter writes one
// object), placed N times, instead of a mesh per geometry each placed N times.
//   tracer_make_instances SCENE N OUT.gltf [--distinct | --one-mesh]
#include <array>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "importers/scene_file.hpp"
#include "scene/builtin.hpp"
#include "scene_writers.hpp"

int main(int argc, char** argv) {
  using namespace tracer;
  if (argc < 4) {
    std::fprintf(stderr, "usage: tracer_make_instances SCENE N OUT.gltf [--distinct | --one-mesh]\n");
    return 2;
  }
  const Scene scene = load_scene_file(argv[1]);
  const long n = std::strtol(argv[2], nullptr, 10);
  if (n < 1 || n > long(UINT32_MAX)) {
    std::fprintf(stderr, "tracer_make_instances: N must be between 1 and 2^32 - 1\n");
    return 2;
  }
  test::GltfWriteOptions options;
  options.distinct_meshes = argc > 4 && std::string(argv[4]) == "--distinct";
  options.one_mesh = argc > 4 && std::string(argv[4]) == "--one-mesh";
  std::vector<std::array<double, 16>> placements;
  for (const Affine& a : grid_placements(scene.bounds, uint32_t(n))) placements.push_back(a.column_major());
  for (uint32_t g = 0; g < scene.geometries.size(); ++g) options.placements[g] = placements;
  test::write_gltf(scene, argv[3], options);
  std::printf("%s: %zu triangles placed %ld times (%.4g)\n", argv[3], scene.size(), n,
              double(scene.size()) * double(n));
  return 0;
}
