#include "frontend/parse.hpp"

#include <charconv>
#include <cmath>
#include <sstream>

#include "base/errors.hpp"
#include "base/whole_number.hpp"

namespace tracer::frontend {

Vec3 parse_vec3(const std::string& flag, const std::string& text) {
  double v[3];
  int n = 0;
  size_t pos = 0;
  for (;;) {
    const size_t comma = text.find(',', pos);
    const std::string part = text.substr(pos, comma == std::string::npos ? std::string::npos : comma - pos);
    double value = 0;
    const WholeNumber read = read_whole_number(part, value);
    if (n == 3 || read == WholeNumber::NotANumber) {
      throw UsageError(flag + ": expected three numbers x,y,z, got '" + text + "'");
    }
    if (read == WholeNumber::OutOfRange || !std::isfinite(value) || std::fabs(value) > 3.4e38) {
      throw UsageError(flag + ": '" + part + "' is out of range (not a finite float) in '" + text + "'");
    }
    v[n++] = value;
    if (comma == std::string::npos) break;
    pos = comma + 1;
  }
  if (n != 3) throw UsageError(flag + ": expected three numbers x,y,z, got '" + text + "'");
  return {float(v[0]), float(v[1]), float(v[2])};
}

Vec3 parse_point(const std::string& flag, const std::string& text) {
  const Vec3 p = parse_vec3(flag, text);
  for (const float c : {p.x, p.y, p.z}) {
    if (std::fabs(c) > kMaxCoordinate) {
      throw UsageError(flag + ": coordinates must lie within +-" + kMaxCoordinateText + ", got '" + text + "'");
    }
  }
  return p;
}

std::pair<int, int> parse_size(const std::string& flag, const std::string& text) {
  const size_t x = text.find('x');
  int v[2] = {0, 0};
  const std::string parts[2] = {text.substr(0, x), x == std::string::npos ? "" : text.substr(x + 1)};
  for (int i = 0; i < 2; ++i) {
    long long n = 0;
    if (read_whole_number(parts[i], n) != WholeNumber::Ok)
      throw UsageError(flag + ": expected WxH (two whole numbers), got '" + text + "'");
    check_range(flag + (i == 0 ? " width" : " height"), n, 1, 16384);
    v[i] = int(n);
  }
  return {v[0], v[1]};
}

std::vector<std::string> split_list(const std::string& flag, const std::string& text) {
  std::vector<std::string> items;
  size_t pos = 0;
  for (;;) {
    const size_t comma = text.find(',', pos);
    std::string item = text.substr(pos, comma == std::string::npos ? std::string::npos : comma - pos);
    if (item.empty()) throw UsageError(flag + ": empty name in '" + text + "'");
    items.push_back(std::move(item));
    if (comma == std::string::npos) return items;
    pos = comma + 1;
  }
}

void check_range(const std::string& flag, long long value, long long lo, long long hi) {
  if (value < lo || value > hi) {
    throw UsageError(flag + ": must be between " + std::to_string(lo) + " and " + std::to_string(hi) + ", got " +
                     std::to_string(value));
  }
}

void check_range_real(const std::string& flag, double value, double lo, double hi, LowEnd low) {
  const bool lo_open = low == LowEnd::Open;
  const bool below = lo_open ? !(value > lo) : !(value >= lo);
  if (below || !(value <= hi) || !std::isfinite(value)) {
    std::ostringstream s;
    s << flag << ": must be " << (lo_open ? "above " : "at least ") << lo << " and at most " << hi << ", got " << value;
    throw UsageError(s.str());
  }
}

}  // namespace tracer::frontend
