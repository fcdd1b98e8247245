// libFuzzer target for the OBJ/MTL loading path: the input is split at the first NUL byte (if
// any) into OBJ text and MTL text. Loading must either succeed with a finite, consistent scene
// or throw InputError; anything else (crash, leak, other exception) is a finding. The OBJ is also
// parsed in chunks of 16 bytes, which must give the same scene, or the same error, as one chunk.
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <string>

#include "accel/bvh/bvh.hpp"
#include "base/errors.hpp"
#include "importers/obj_loader.hpp"
#include "scene/scene_checksum.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string input(reinterpret_cast<const char*>(data), size);
  const size_t nul = input.find('\0');
  const std::string obj = input.substr(0, nul);
  const std::string mtl = nul == std::string::npos ? "" : input.substr(nul + 1);
  const auto quiet = [](const std::string&) {};
  tracer::LoadLimits chunked;
  chunked.chunk_bytes = 16;
  std::string chunked_error;
  tracer::Scene in_chunks;
  try {
    in_chunks = tracer::load_obj_from_string(obj, mtl, "fuzz.obj", quiet, chunked);
  } catch (const tracer::InputError& e) {
    chunked_error = e.what();
  }
  try {
    const tracer::Scene scene = tracer::load_obj_from_string(obj, mtl, "fuzz.obj", quiet);
    if (!chunked_error.empty() || tracer::scene_checksum(scene) != tracer::scene_checksum(in_chunks) ||
        scene.tri_geom != in_chunks.tri_geom || scene.tri_prim != in_chunks.tri_prim) {
      std::abort();
    }
    for (const tracer::Triangle& t : scene.triangles) {
      if (!tracer::is_finite(t.v0) || !tracer::is_finite(t.v1) || !tracer::is_finite(t.v2)) std::abort();
    }
    if (scene.tri_material.size() != scene.size()) std::abort();
    for (uint32_t m : scene.tri_material) {
      if (m >= scene.materials.size()) std::abort();
    }
    if (scene.size() < 2000) {  // and the tree built over it must hold
      const tracer::Bvh bvh(scene, tracer::BvhBuildOptions{});
      if (!bvh.validate().empty()) std::abort();
    }
  } catch (const tracer::InputError& e) {
    if (chunked_error != e.what()) std::abort();
  }
  return 0;
}
