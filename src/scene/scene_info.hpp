// What `tracer info` tells of a scene: its counts, materials, lights, cameras and bounds. Made
// from a loaded Scene, or by a loader that can count without placing every triangle (a glTF's
// instances: each node counted once, however often it is reached).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "scene/scene.hpp"

namespace tracer {

struct SceneInfo {
  std::string source;
  uint64_t triangles = 0, degenerate = 0, vertices = 0, geometries = 0;  // triangles: as placed
  // An instanced scene's meshes (each kept once), their triangles and the instances placing them;
  // all 0 for a flat scene.
  uint64_t unique_triangles = 0, meshes = 0, instances = 0;
  // The scene's arrays and an accelerator's (bvh8's at medium quality) over them, estimated.
  uint64_t estimated_bytes = 0;
  std::vector<std::string> materials;
  std::vector<Light> lights;          // every light listed
  uint64_t unlisted_area_lights = 0;  // emissive geometries counted but not placed (a glTF's)
  std::vector<CameraSpec> cameras;
  Aabb bounds;
};

inline SceneInfo info_of(const Scene& scene) {
  SceneInfo info;
  info.source = scene.source;
  info.triangles = scene.instanced_size();
  if (scene.instanced()) {
    info.unique_triangles = scene.size();
    info.meshes = scene.meshes.size();
    info.instances = scene.instances.size();
  }
  info.degenerate = scene.degenerate_count;
  info.vertices = scene.vertex_count;
  info.geometries = scene.geometries.size();
  for (const Material& m : scene.materials) info.materials.push_back(m.name);
  info.lights = scene.lights;
  info.cameras = scene.cameras;
  info.bounds = scene.bounds;
  return info;
}

}  // namespace tracer
