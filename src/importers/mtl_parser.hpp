// The MTL format (Wavefront's material library), read as tinyobjloader reads the files of real
// exporters, and strictly where a value would make the image wrong. Liberal: letters glued to a
// number (`0.5c`), text after what a statement takes (`Tr 0  illum 2`), statements before the
// first `newmtl` and unknown texture options are dropped, each kind said once per file with its
// lines. Strict, an error naming file:line: no number where one is required (`Kd red`), two
// values of a colour, nan, inf, values out of range. Tokens are separated by any run of spaces and
// tabs; `#` starts a comment anywhere on a line (exporters glue them to numbers). Where tracer
// reads a file otherwise than tinyobjloader, docs/RELIABILITY.md says why (the differential test
// in tests/test_mtl.cpp holds the rest equal).
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "base/errors.hpp"
#include "math/vec.hpp"
#include "scene/value_limits.hpp"

namespace tracer {

// One `newmtl` block as written; defaults are the format's (and tinyobjloader's): black colours,
// Ns 1, Ni 1, d 1, illum 0.
struct MtlMaterial {
  std::string name;
  Vec3 ka{0.0f}, kd{0.0f}, ks{0.0f}, ke{0.0f}, tf{0.0f};
  float ns = 1.0f, ni = 1.0f, dissolve = 1.0f;
  int illum = 0;
  std::string diffuse_map;       // map_Kd's file name, its options dropped
  std::string bump_map;          // map_bump / bump
  float bump_multiplier = 1.0f;  // its -bm
  std::string specular_map;      // map_Ks: scales Ks
  std::string shininess_map;     // map_Ns: scales Ns
  std::string emissive_map;      // map_Ke: scales Ke
  std::string normal_map;        // norm: a tangent-space normal map (the PBR extension's)
  float normal_scale = 1.0f;     // its -bm
  size_t line = 0;               // where `newmtl` stands
};

// The materials of one file, and its warnings: each one line that names the file and the lines.
struct MtlFile {
  std::vector<MtlMaterial> materials;
  std::vector<std::string> warnings;
};

// Parses MTL text; `name` stands for the file in messages. Throws InputError("name:line: ...").
// Statements the renderer does not use (map_Ka, Pr, ...) are skipped; a spectral colour
// (`Kd spectral file.rfl`) is an error, as tracer renders RGB.
MtlFile parse_mtl(std::string_view text, const std::string& name, CancelFlag cancel = nullptr);

}  // namespace tracer
