// PLY loading (ASCII and binary of either byte order), the format of the Stanford scans: the
// `vertex` element's x, y, z and optional normals (nx, ny, nz) and texture coordinates (u, v;
// s, t; texture_u, texture_v), the `face` element's index lists (vertex_indices or
// vertex_index, any integer types), polygons triangulated; other elements and properties are
// skipped. A PLY has no materials: one grey diffuse default, as an OBJ without an MTL.
// tracer reads PLY itself rather than through assimp: docs/FORMATS.md gives the measurement.
#pragma once

#include <string>
#include <string_view>

#include "base/errors.hpp"
#include "importers/load_limits.hpp"
#include "importers/warning_log.hpp"
#include "scene/scene.hpp"

namespace tracer {

// Throws InputError naming the file and, in the header or an ASCII body, the line; memory is
// bounded by the file's size (counts the file cannot hold are refused before anything is
// allocated), and faces whose triangles would not fit limits.max_memory are refused at the
// header. Cancelled when `cancel` is set during loading.
Scene load_ply(const std::string& path, const WarningSink& warn = {}, CancelFlag cancel = nullptr,
               const LoadLimits& limits = {}, LoadPhases* phases = nullptr);

// The same from memory (fuzzing, tests); `name` stands for the file in messages.
Scene load_ply_from_memory(std::string_view bytes, const std::string& name, const WarningSink& warn = {},
                           const LoadLimits& limits = {});

}  // namespace tracer
