// tinygltf (Debian's libtinygltf-dev header) as tracer compiles it: every file that includes it
// sees the same configuration. Images are neither decoded nor read by tinygltf: tracer reads and
// decodes them itself within its texture limits, and resolves external URIs inside the scene's
// folder only. The implementation is compiled into tracer (tinygltf_impl.cpp) rather than taken
// from libtinygltf.so so that the fuzz targets instrument the parser they exercise.
#pragma once

#define TINYGLTF_NO_STB_IMAGE
#define TINYGLTF_NO_STB_IMAGE_WRITE
#define TINYGLTF_NO_EXTERNAL_IMAGE
#include <tiny_gltf.h>
