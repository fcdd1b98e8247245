// libFuzzer target for the MTL path: the input is an MTL file that a fixed one-triangle OBJ
// names and uses. Loading must either succeed with finite materials, every triangle's material
// in range, or throw InputError; anything else (crash, leak, other exception) is a finding. And
// the parser must read the input as tinyobjloader does (tests/oracle/mtl_oracle.hpp).
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <optional>
#include <string>

#include "base/errors.hpp"
#include "importers/obj_loader.hpp"
#include "oracle/mtl_oracle.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string mtl(reinterpret_cast<const char*>(data), size);
  if (const std::optional<std::string> d = tracer::oracle::mtl_disagreement(mtl)) {
    std::fprintf(stderr, "tracer and tinyobjloader disagree: %s\n", d->c_str());
    std::abort();
  }
  // The OBJ uses the first material name the input defines, so the material is really applied.
  std::string used = "m";
  if (const size_t at = mtl.find("newmtl "); at != std::string::npos) {
    const size_t end = mtl.find_first_of("\r\n", at);
    used = mtl.substr(at + 7, end == std::string::npos ? std::string::npos : end - at - 7);
  }
  const std::string obj = "mtllib fuzz.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl " + used + "\nf 1 2 3\n";
  try {
    const tracer::Scene scene = tracer::load_obj_from_string(obj, mtl, "fuzz.obj", [](const std::string&) {});
    for (const tracer::Material& m : scene.materials) {
      if (!tracer::is_finite(m.kd) || !tracer::is_finite(m.ks) || !tracer::is_finite(m.ke) || !std::isfinite(m.ni))
        std::abort();
    }
    for (uint32_t id : scene.tri_material) {
      if (id >= scene.materials.size()) std::abort();
    }
    for (const tracer::Light& l : scene.lights) {
      if (!tracer::is_finite(l.position) || !tracer::is_finite(l.power)) std::abort();
    }
  } catch (const tracer::InputError&) {
  }
  return 0;
}
