// libFuzzer target for glTF loading (.gltf JSON or binary .glb, from memory: only data: URIs
// resolve). Loading must either succeed with a finite, consistent scene or throw InputError;
// anything else (crash, leak, other exception, an allocation past libFuzzer's limit) is a finding.
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "base/errors.hpp"
#include "importers/gltf_loader.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  // Within libFuzzer's -rss_limit_mb=2048, as a render is within --max-memory-mib: a node tree
  // that expands past it is refused by its estimate, before it is expanded. 64 MiB, not more: a
  // few hundred bytes of nodes may expand to that many triangles, which with coverage
  // instrumentation took over libFuzzer's 10 s at 512 MiB (2^21 triangles).
  tracer::LoadLimits limits;
  limits.max_memory = uint64_t(64) << 20;
  limits.accel_bytes_per_triangle = 96;
  try {
    const tracer::Scene scene = tracer::load_gltf_from_memory(
        std::string_view(reinterpret_cast<const char*>(data), size), "fuzz.gltf", [](const std::string&) {}, limits);
    for (const tracer::Triangle& t : scene.triangles) {
      if (!tracer::is_finite(t.v0) || !tracer::is_finite(t.v1) || !tracer::is_finite(t.v2)) std::abort();
    }
    if (scene.tri_material.size() != scene.size() || scene.tri_geom.size() != scene.size()) std::abort();
    if (!scene.corner_normals.empty() && scene.corner_normals.size() != 3 * scene.size()) std::abort();
    if (!scene.corner_uvs.empty() && scene.corner_uvs.size() != 3 * scene.size()) std::abort();
    for (uint32_t m : scene.tri_material) {
      if (m >= scene.materials.size()) std::abort();
    }
    for (const tracer::Material& m : scene.materials) {
      for (const tracer::TextureSlot* t : m.slots())
        if (t->present() && (t->texture >= scene.textures.size() || t->uv_set > 1)) std::abort();
    }
  } catch (const tracer::InputError&) {
  }
  return 0;
}
