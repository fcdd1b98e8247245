// tinyobjloader as the reference reader of MTL files: what it loads, tracer loads with the same
// values, or refuses for a reason that would make the image wrong. Shared by the differential test
// (tests/test_mtl.cpp) and the MTL fuzz target.
#pragma once

#include <optional>
#include <string>

namespace tracer::oracle {

// The text tinyobjloader is given for an MTL text: the format's meaning written out where
// tinyobjloader departs from it (docs/RELIABILITY.md, "MTL: where tracer reads otherwise"):
// `#` starts a comment anywhere; a colour of one value is grey; a material's map_Kd without Kd
// is grey 0.6 in every material (tinyobjloader forgets to reset this after the first Kd); a
// material's name is its first word; a NUL ends a line. Colours written as CIE XYZ, which
// tinyobjloader does not read, are not compared.
std::string mtl_as_the_format_means(const std::string& text);

// Loads `text` with tracer's parser and (after mtl_as_the_format_means) with tinyobjloader's
// LoadMtl; returns a description of the first disagreement, or nullopt. A refusal by tracer is a
// disagreement unless its message is one of the errors that keep a wrong image from being made
// (a missing or malformed number, nan, inf, a value out of range, a colour of two values, a
// texture statement without a file name, a spectral colour, `newmtl` without a name).
// `*refused` (if given) tells whether tracer refused the text.
std::optional<std::string> mtl_disagreement(const std::string& text, bool* refused = nullptr);

}  // namespace tracer::oracle
