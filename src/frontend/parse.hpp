// Flag-value parsing shared by the commands: each failure is a one-line UsageError naming the flag.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "math/vec.hpp"

namespace tracer::frontend {

Vec3 parse_vec3(const std::string& flag, const std::string& text);
// "WxH", each 1-16384.
std::pair<int, int> parse_size(const std::string& flag, const std::string& text);
// A comma-separated list with no empty item.
std::vector<std::string> split_list(const std::string& flag, const std::string& text);
// A position (--eye, --look, --light): three finite numbers within the supported coordinate range.
Vec3 parse_point(const std::string& flag, const std::string& text);
void check_range(const std::string& flag, long long value, long long lo, long long hi);
// Whether a range's low end is a value it holds (Closed) or only bounds it (Open: --exposure 0 is refused).
enum class LowEnd { Closed, Open };
void check_range_real(const std::string& flag, double value, double lo, double hi, LowEnd low = LowEnd::Closed);

}  // namespace tracer::frontend
