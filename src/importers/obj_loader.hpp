// OBJ/MTL loading: the bytes are read once and parsed in parallel chunks (importers/obj_parser.hpp),
// the MTL files by the strict MTL parser, the textures read and decoded while the geometry is
// parsed; every error names the file and line.
#pragma once

#include <functional>
#include <string>

#include "base/errors.hpp"
#include "base/read_input.hpp"
#include "importers/load_limits.hpp"
#include "importers/obj_parser.hpp"
#include "importers/warning_log.hpp"
#include "scene/scene.hpp"
#include "scene/texture.hpp"

namespace tracer {

// Loads an OBJ file (and its MTL) into a finalized Scene. `path` may be any readable file,
// including a pipe; "-" reads standard input (MTL files then resolve from the current directory).
// Throws InputError with a one-line message naming the file and, where there is one, the line;
// Cancelled when `cancel` is set during loading.
Scene load_obj(const std::string& path, const WarningSink& warn = {}, CancelFlag cancel = nullptr,
               const LoadLimits& limits = {}, LoadPhases* phases = nullptr);

// The same from memory (fuzzing, tests); `name` stands for the file in messages, and `mtl_text`
// serves every `mtllib` the OBJ names.
Scene load_obj_from_string(const std::string& obj_text, const std::string& mtl_text, const std::string& name,
                           const WarningSink& warn = {}, const LoadLimits& limits = {});

}  // namespace tracer
