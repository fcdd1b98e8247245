// A fingerprint of everything a render reads from a scene (triangles, materials, normals,
// texture coordinates, textures, lights), so processes that each load "the same" scene (the
// ranks of an MPI job, on different machines) can check that they did before rendering.
#pragma once

#include <cstdint>

#include "scene/scene.hpp"

namespace tracer {

// 64-bit FNV-1a over the scene's data in a fixed order; the file names and paths do not count.
uint64_t scene_checksum(const Scene& scene);
// The same of an environment map (--env-map): its size, rotation and texels. Ranks given one path
// in different working directories read different files.
uint64_t environment_checksum(const EnvironmentMap& map);

}  // namespace tracer
