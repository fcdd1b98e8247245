// What a scene load may read and take, and where its time went: shared by every importer.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>

#include "base/errors.hpp"
#include "base/memory_limit.hpp"
#include "base/read_input.hpp"
#include "scene/instances.hpp"
#include "scene/scene.hpp"
#include "scene/texture.hpp"

namespace tracer {

// body(i) for every i in [0, count), possibly in parallel. The loader knows nothing of threads; the
// caller hands it an executor's loop.
using ForEach = std::function<void(size_t count, const std::function<void(size_t)>& body)>;
inline void sequential_for_each(size_t count, const std::function<void(size_t)>& body) {
  for (size_t i = 0; i < count; ++i) body(i);
}

// What an instance takes at the peak of a render's build: the Instance, and the top-level tree's
// share (its box, the builder's reference and scratch node share, the tree's node share).
inline constexpr uint64_t kBytesPerInstance = sizeof(Instance) + 24 + 32 + 128 + 40;

// What a load may read (the scene file's size, MTL files 64 MiB each, the textures' texels), and
// the loop it reads and decodes textures with.
struct LoadLimits {
  uint64_t max_obj_bytes = kDefaultMaxInputBytes;
  TextureLimits textures;
  ForEach for_each = sequential_for_each;
  size_t chunk_bytes = 0;     // the OBJ parser's chunk size; 0: from the file's size
  bool read_textures = true;  // false: no map_Kd file is read, materials use Kd (geometry-only loads)
  // What the scene and the accelerator built over it may take. A loader that knows a scene's size
  // before allocating it (glTF's instances, counted before they are expanded) refuses one whose
  // estimate, its arrays plus accel_bytes_per_triangle for each triangle, is above max_memory.
  uint64_t max_memory = UINT64_MAX;
  uint64_t accel_bytes_per_triangle = 0;  // 0: no accelerator follows (tracer info)
  // A glTF that places a mesh more than once keeps it once, placed by instances (Scene::instances);
  // false: every placement is expanded into world-space triangles (for the accelerators that
  // trace no instances).
  bool keep_instances = true;
};

// Throws InputError when `triangles` (with corner normals and uvs where the file gives them) and
// the accelerator over them would take more than limits.max_memory: called by the loaders that
// count a file's triangles before assembling the scene (OBJ after its parse, PLY from its header),
// so a scene that will not fit is refused before its arrays are allocated.
inline void refuse_past_memory(const LoadLimits& limits, const std::string& name, uint64_t triangles, bool normals,
                               bool uvs, bool colors = false) {
  const uint64_t per_triangle = Scene::bytes_per_triangle(normals, uvs, colors) + limits.accel_bytes_per_triangle;
  const uint64_t bytes = triangles > UINT64_MAX / per_triangle ? UINT64_MAX : triangles * per_triangle;
  if (bytes <= limits.max_memory) return;
  throw InputError(memory_refusal(name + ": its " + std::to_string(triangles) + " triangles" +
                                      (limits.accel_bytes_per_triangle ? " and their accelerator" : ""),
                                  bytes, limits.max_memory));
}

// Where a load's time went (--stats): reading the bytes, parsing and checking the OBJ and its
// MTL, reading and decoding the textures, and assembling the scene's arrays.
struct LoadPhases {
  double read_ms = 0.0, parse_ms = 0.0, textures_ms = 0.0, assembly_ms = 0.0;
};

}  // namespace tracer
