// libFuzzer target for PLY loading (ASCII and binary). Loading must either succeed with a
// finite, consistent scene or throw InputError; anything else (crash, leak, other exception, an
// allocation past libFuzzer's limit) is a finding.
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "base/errors.hpp"
#include "importers/ply_loader.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    const tracer::Scene scene = tracer::load_ply_from_memory(
        std::string_view(reinterpret_cast<const char*>(data), size), "fuzz.ply", [](const std::string&) {});
    for (const tracer::Triangle& t : scene.triangles) {
      if (!tracer::is_finite(t.v0) || !tracer::is_finite(t.v1) || !tracer::is_finite(t.v2)) std::abort();
    }
    if (scene.tri_material.size() != scene.size() || scene.materials.size() != 1) std::abort();
    if (!scene.corner_normals.empty() && scene.corner_normals.size() != 3 * scene.size()) std::abort();
    if (!scene.corner_uvs.empty() && scene.corner_uvs.size() != 3 * scene.size()) std::abort();
  } catch (const tracer::InputError&) {
  }
  return 0;
}
