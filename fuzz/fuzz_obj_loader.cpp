// libFuzzer target for the OBJ/MTL loading path: the input is split at the first NUL byte (if
// any) into OBJ text and MTL text. Loading must either succeed with a finite, consistent scene
// or throw InputError; anything else (crash, leak, other exception) is a finding.
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <string>

#include "accel/bvh.hpp"
#include "base/errors.hpp"
#include "scene/obj_loader.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string input(reinterpret_cast<const char*>(data), size);
  const size_t nul = input.find('\0');
  const std::string obj = input.substr(0, nul);
  const std::string mtl = nul == std::string::npos ? "" : input.substr(nul + 1);
  try {
    const tracer::Scene scene = tracer::load_obj_from_string(obj, mtl, "fuzz.obj", [](const std::string&) {});
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
  } catch (const tracer::InputError&) {
  }
  return 0;
}
