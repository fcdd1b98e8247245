// OBJ/MTL loading through tinyobjloader, with the validation tinyobjloader does not do.
#pragma once

#include <functional>
#include <string>

#include "scene/scene.hpp"

namespace tracer {

// Receives non-fatal problems (a missing MTL or texture); default prints to stderr.
using WarningSink = std::function<void(const std::string&)>;

// Loads an OBJ file (and its MTL) into a finalized Scene. Throws InputError with a one-line
// message naming the file and, where there is one, the line.
Scene load_obj(const std::string& path, const WarningSink& warn = {});

// The same from memory (fuzzing, tests); `name` stands for the file in messages, and `mtl_text`
// serves every `mtllib` the OBJ names.
Scene load_obj_from_string(const std::string& obj_text, const std::string& mtl_text,
                           const std::string& name, const WarningSink& warn = {});

}  // namespace tracer
