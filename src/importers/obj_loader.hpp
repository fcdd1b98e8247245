// OBJ/MTL loading: the bytes are read once and parsed in parallel chunks (importers/obj_parser.hpp),
// the MTL files by the strict MTL parser, the textures read and decoded while the geometry is
// parsed; every error names the file and line.
#pragma once

#include <functional>
#include <string>

#include "base/errors.hpp"
#include "base/read_input.hpp"
#include "importers/obj_parser.hpp"
#include "scene/scene.hpp"
#include "scene/texture.hpp"

namespace tracer {

// Receives non-fatal problems (a missing MTL or texture), one line per kind of problem with a
// count and the first place; the default prints to stderr.
using WarningSink = std::function<void(const std::string&)>;

// Loads an OBJ file (and its MTL) into a finalized Scene. `path` may be any readable file,
// including a pipe; "-" reads standard input (MTL files then resolve from the current directory).
// Throws InputError with a one-line message naming the file and, where there is one, the line;
// Cancelled when `cancel` is set during loading.
// What a load may read (the OBJ's size, MTL files 64 MiB each, the textures' texels), and the
// loop it reads and decodes textures with.
struct LoadLimits {
  uint64_t max_obj_bytes = kDefaultMaxInputBytes;
  TextureLimits textures;
  ForEach for_each = sequential_for_each;
  size_t chunk_bytes = 0;     // the OBJ parser's chunk size; 0: from the file's size
  bool read_textures = true;  // false: no map_Kd file is read, materials use Kd (geometry-only loads)
};

// Where a load's time went (--stats): reading the bytes, parsing and checking the OBJ and its
// MTL, reading and decoding the textures, and assembling the scene's arrays.
struct LoadPhases {
  double read_ms = 0.0, parse_ms = 0.0, textures_ms = 0.0, assembly_ms = 0.0;
};

Scene load_obj(const std::string& path, const WarningSink& warn = {}, CancelFlag cancel = nullptr,
               const LoadLimits& limits = {}, LoadPhases* phases = nullptr);

// The same from memory (fuzzing, tests); `name` stands for the file in messages, and `mtl_text`
// serves every `mtllib` the OBJ names.
Scene load_obj_from_string(const std::string& obj_text, const std::string& mtl_text, const std::string& name,
                           const WarningSink& warn = {}, const LoadLimits& limits = {});

}  // namespace tracer
