// What a render writes (-o, each frame's image, --stats-json), checked before the render: a known
// format, writable, and never a file the render reads.
#pragma once

#include <string>

#include "frontend/render_args.hpp"

namespace tracer::frontend {

// Two paths name the same file: the same inode if both exist, else the same absolute path.
bool same_file(const std::string& a, const std::string& b);
// -o and --stats-json: known formats, writable, and neither of them the input scene or each other.
void check_outputs(const RenderArgs& args);
// Once the scene is loaded: no output (every frame's, --stats-json) is a file the load read (the
// OBJ, its MTL files and textures, a views file), by identity; throws UsageError.
void check_outputs_against_inputs(const RenderArgs& args);
// The output of frame `frame`: `output` itself for a single frame, else NAME-0007.EXT (more digits past 10,000 frames).
std::string frame_output(const std::string& output, int frame, int frames);

}  // namespace tracer::frontend
