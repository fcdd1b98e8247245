#include "importers/ply_loader.hpp"

#include <fast_float/fast_float.h>

#include <algorithm>
#include <array>
#include <bit>
#include <charconv>
#include <cmath>
#include <cstring>
#include <optional>

#include "base/read_input.hpp"
#include "base/stopwatch.hpp"
#include "base/text.hpp"
#include "importers/indexed_mesh.hpp"
#include "math/srgb.hpp"
#include "math/triangulate.hpp"

namespace tracer {
namespace {

enum class PlyType : uint8_t { Int8, Uint8, Int16, Uint16, Int32, Uint32, Float32, Float64 };
enum class PlyFormat : uint8_t { Ascii, BinaryLittle, BinaryBig };

size_t size_of(PlyType t) {
  constexpr size_t sizes[] = {1, 1, 2, 2, 4, 4, 4, 8};
  return sizes[size_t(t)];
}
bool is_integer(PlyType t) { return t != PlyType::Float32 && t != PlyType::Float64; }

std::optional<PlyType> type_named(std::string_view s) {
  struct Name {
    const char* name;
    PlyType type;
  };
  static constexpr Name names[] = {
      {"char", PlyType::Int8},      {"int8", PlyType::Int8},       {"uchar", PlyType::Uint8},
      {"uint8", PlyType::Uint8},    {"short", PlyType::Int16},     {"int16", PlyType::Int16},
      {"ushort", PlyType::Uint16},  {"uint16", PlyType::Uint16},   {"int", PlyType::Int32},
      {"int32", PlyType::Int32},    {"uint", PlyType::Uint32},     {"uint32", PlyType::Uint32},
      {"float", PlyType::Float32},  {"float32", PlyType::Float32}, {"double", PlyType::Float64},
      {"float64", PlyType::Float64}};
  for (const Name& n : names)
    if (s == n.name) return n.type;
  return std::nullopt;
}

struct PlyProperty {
  std::string name;
  PlyType type = PlyType::Float32;
  bool list = false;
  PlyType count_type = PlyType::Uint8;
};

struct PlyElement {
  std::string name;
  uint64_t count = 0;
  uint64_t line = 0;
  std::vector<PlyProperty> properties;
  int find(std::string_view n) const {
    for (size_t i = 0; i < properties.size(); ++i)
      if (properties[i].name == n) return int(i);
    return -1;
  }
};

struct PlyHeader {
  PlyFormat format = PlyFormat::Ascii;
  std::vector<PlyElement> elements;
  size_t body = 0;         // byte offset of the first byte after end_header's line
  uint64_t body_line = 0;  // line number of the body's first line (ASCII)
};

std::vector<std::string_view> tokens(std::string_view line) {
  std::vector<std::string_view> out;
  size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t' || line[i] == '\r')) ++i;
    const size_t start = i;
    while (i < line.size() && line[i] != ' ' && line[i] != '\t' && line[i] != '\r') ++i;
    if (i > start) out.push_back(line.substr(start, i - start));
  }
  return out;
}

PlyHeader parse_header(std::string_view bytes, const std::string& name) {
  PlyHeader h;
  size_t pos = 0;
  uint64_t line_no = 0;
  bool have_format = false;
  const auto fail = [&](const std::string& what) -> InputError {
    return InputError(name + ":" + std::to_string(line_no) + ": " + what);
  };
  if (bytes.empty()) throw InputError(name + ": an empty file, not a PLY file");
  while (true) {
    if (pos >= bytes.size()) throw fail("the header has no end_header line");
    const size_t end = std::min(bytes.find('\n', pos), bytes.size());
    const std::string_view line = bytes.substr(pos, end - pos);
    pos = end + 1;
    ++line_no;
    const std::vector<std::string_view> t = tokens(line);
    if (line_no == 1) {
      if (t.size() != 1 || t[0] != "ply") throw fail("not a PLY file (its first line is not 'ply')");
      continue;
    }
    if (t.empty()) continue;
    if (t[0] == "comment" || t[0] == "obj_info") continue;
    if (t[0] == "end_header") break;
    if (t[0] == "format") {
      if (t.size() != 3 || t[2] != "1.0")
        throw fail("expected 'format <ascii|binary_little_endian|binary_big_endian> 1.0'");
      if (t[1] == "ascii") {
        h.format = PlyFormat::Ascii;
      } else if (t[1] == "binary_little_endian") {
        h.format = PlyFormat::BinaryLittle;
      } else if (t[1] == "binary_big_endian") {
        h.format = PlyFormat::BinaryBig;
      } else {
        throw fail("unknown format " + in_quotes(t[1]));
      }
      have_format = true;
    } else if (t[0] == "element") {
      if (t.size() != 3) throw fail("expected 'element <name> <count>'");
      PlyElement e;
      e.name = std::string(t[1]);
      e.line = line_no;
      const auto [p, ec] = std::from_chars(t[2].data(), t[2].data() + t[2].size(), e.count);
      if (ec != std::errc{} || p != t[2].data() + t[2].size()) throw fail("malformed element count " + in_quotes(t[2]));
      h.elements.push_back(std::move(e));
    } else if (t[0] == "property") {
      if (h.elements.empty()) throw fail("a property before any element");
      PlyProperty prop;
      if (t.size() == 5 && t[1] == "list") {
        const std::optional<PlyType> count = type_named(t[2]), item = type_named(t[3]);
        if (!count || !item) throw fail("unknown property type in " + in_quotes(line));
        if (!is_integer(*count)) throw fail("a list's count must be an integer type");
        prop = {std::string(t[4]), *item, true, *count};
      } else if (t.size() == 3) {
        const std::optional<PlyType> type = type_named(t[1]);
        if (!type) throw fail("unknown property type " + in_quotes(t[1]));
        prop = {std::string(t[2]), *type, false, PlyType::Uint8};
      } else {
        throw fail("expected 'property <type> <name>' or 'property list <type> <type> <name>'");
      }
      if (h.elements.back().find(prop.name) >= 0) {
        throw fail("property " + in_quotes(prop.name) + " declared twice in element " +
                   in_quotes(h.elements.back().name));
      }
      h.elements.back().properties.push_back(std::move(prop));
    } else {  // a line tracer cannot place might declare data: the rows would be misread
      throw fail("unknown header line " + in_quotes(t[0]));
    }
  }
  if (!have_format) throw InputError(name + ": the header has no format line");
  h.body = std::min(pos, bytes.size());
  h.body_line = line_no + 1;
  return h;
}

// Reads the body's values in order, binary or ASCII, bounds-checked.
class BodyReader {
 public:
  BodyReader(std::string_view bytes, const PlyHeader& h, const std::string& name)
      : bytes_(bytes), pos_(h.body), format_(h.format), line_(h.body_line), name_(name) {}

  size_t remaining() const { return bytes_.size() - pos_; }
  bool ascii() const { return format_ == PlyFormat::Ascii; }

  double value(PlyType type, const char* what) {
    if (ascii()) return ascii_value(type, what);
    const size_t n = size_of(type);
    if (remaining() < n) throw fail(std::string("the file ends inside ") + what);
    unsigned char b[8];
    std::memcpy(b, bytes_.data() + pos_, n);
    pos_ += n;
    if ((format_ == PlyFormat::BinaryBig) != (std::endian::native == std::endian::big)) std::reverse(b, b + n);
    switch (type) {
      case PlyType::Int8:
        return double(int8_t(b[0]));
      case PlyType::Uint8:
        return double(b[0]);
      case PlyType::Int16:
        return double(load<int16_t>(b));
      case PlyType::Uint16:
        return double(load<uint16_t>(b));
      case PlyType::Int32:
        return double(load<int32_t>(b));
      case PlyType::Uint32:
        return double(load<uint32_t>(b));
      case PlyType::Float32:
        return double(load<float>(b));
      case PlyType::Float64:
        return load<double>(b);
    }
    return 0.0;
  }

  // Before a row: blank lines are passed over (ASCII).
  void begin_row() {
    if (!ascii()) return;
    while (pos_ < bytes_.size() &&
           (bytes_[pos_] == ' ' || bytes_[pos_] == '\t' || bytes_[pos_] == '\r' || bytes_[pos_] == '\n')) {
      if (bytes_[pos_] == '\n') ++line_;
      ++pos_;
    }
  }
  // After a row: its line ends here (ASCII).
  void end_row(const std::string& element) {
    if (!ascii()) return;
    skip_blanks();
    if (pos_ < bytes_.size() && bytes_[pos_] != '\n') {
      throw fail("more values than element " + in_quotes(element) + " declares properties (" +
                 in_quotes(bytes_.substr(pos_, std::min<size_t>(20, bytes_.find_first_of("\r\n", pos_) - pos_))) +
                 " is one too many)");
    }
    if (pos_ < bytes_.size()) {
      ++pos_;
      ++line_;
    }
  }

  InputError fail(const std::string& what) const {
    return InputError(ascii() ? name_ + ":" + std::to_string(line_) + ": " + what : name_ + ": " + what);
  }

 private:
  template <class T>
  static T load(const unsigned char* b) {
    T v;
    std::memcpy(&v, b, sizeof v);
    return v;
  }

  // The values of a row stand on one line: a value is read within the line, and end_row() checks
  // that the line holds no more, so that a row with an extra value is named at its line instead of
  // shifting every row after it.
  void skip_blanks() {
    while (pos_ < bytes_.size() && (bytes_[pos_] == ' ' || bytes_[pos_] == '\t' || bytes_[pos_] == '\r')) ++pos_;
  }

  double ascii_value(PlyType type, const char* what) {
    skip_blanks();
    if (pos_ < bytes_.size() && bytes_[pos_] == '\n') {
      throw fail(std::string("the line ends inside ") + what + " (fewer values than its element's properties)");
    }
    const size_t start = pos_;
    while (pos_ < bytes_.size() && bytes_[pos_] != ' ' && bytes_[pos_] != '\t' && bytes_[pos_] != '\r' &&
           bytes_[pos_] != '\n')
      ++pos_;
    if (pos_ == start) throw fail(std::string("the file ends inside ") + what);
    const char* first = bytes_.data() + start;
    const char* last = bytes_.data() + pos_;
    double v = 0.0;
    if (is_integer(type)) {
      long long i = 0;
      const auto [p, ec] = std::from_chars(first, last, i);
      if (ec != std::errc{} || p != last) throw fail("malformed integer " + in_quotes({first, size_t(last - first)}));
      v = double(i);
    } else {
      const auto r = fast_float::from_chars(first, last, v);
      if (r.ec != std::errc{} || r.ptr != last)
        throw fail("malformed number " + in_quotes({first, size_t(last - first)}));
    }
    return v;
  }

  std::string_view bytes_;
  size_t pos_;
  PlyFormat format_;
  uint64_t line_;
  const std::string& name_;
};

// The fewest bytes a row of `e` takes: its scalars' sizes and its lists' counts (binary), or
// two characters a value, a digit and a separator (ASCII).
uint64_t min_row_bytes(const PlyElement& e, bool ascii) {
  uint64_t bytes = 0;
  for (const PlyProperty& p : e.properties) bytes += ascii ? 2 : size_of(p.list ? p.count_type : p.type);
  return bytes;
}

const char* const kUv[][2] = {{"u", "v"}, {"s", "t"}, {"texture_u", "texture_v"}, {"texture_s", "texture_t"}};

Scene load(std::string_view bytes, const std::string& name, const WarningSink& warn_in, CancelFlag cancel,
           const LoadLimits& limits, LoadPhases* phases) {
  const WarningSink warn = warn_in ? warn_in : WarningSink(default_warning);
  const auto parse_start = Clock::now();
  WarningLog warnings;
  const PlyHeader header = parse_header(bytes, name);
  BodyReader in(bytes, header, name);
  IndexedMesh mesh;
  bool have_vertices = false, have_faces = false;
  std::vector<double> row;
  std::vector<std::array<uint32_t, 3>> triangles;
  std::vector<Vec3> corners;
  std::vector<uint32_t> polygon;
  for (const PlyElement& e : header.elements) {
    // Refused before anything is allocated: a count the rest of the file cannot hold.
    const uint64_t row_bytes = min_row_bytes(e, in.ascii());
    if (row_bytes > 0 && e.count > (in.remaining() + 1) / row_bytes) {
      throw InputError(name + ":" + std::to_string(e.line) + ": element " + in_quotes(e.name) + " declares " +
                       std::to_string(e.count) + " rows, more than the " + std::to_string(in.remaining()) +
                       " bytes after the header can hold");
    }
    const bool is_vertex = e.name == "vertex" && !have_vertices;
    const bool is_face = e.name == "face" && !have_faces;
    int x = -1, y = -1, z = -1, nx = -1, ny = -1, nz = -1, u = -1, v = -1, list = -1;
    int rgb[3] = {-1, -1, -1};
    float rgb_scale[3] = {1.0f, 1.0f, 1.0f};  // an integer channel's largest value, 1 for floats
    if (is_vertex) {
      x = e.find("x"), y = e.find("y"), z = e.find("z");
      if (x < 0 || y < 0 || z < 0) throw InputError(name + ":" + std::to_string(e.line) + ": vertex has no x, y and z");
      nx = e.find("nx"), ny = e.find("ny"), nz = e.find("nz");
      if (nx < 0 || ny < 0 || nz < 0) nx = ny = nz = -1;
      for (const auto& pair : kUv) {
        if (e.find(pair[0]) >= 0 && e.find(pair[1]) >= 0) {
          u = e.find(pair[0]), v = e.find(pair[1]);
          break;
        }
      }
      // Vertex colours: integer channels as sRGB codes (as Blender's importer reads them), float
      // channels as linear values in [0, 1].
      for (const auto& names : {std::array<const char*, 3>{"red", "green", "blue"}, {"r", "g", "b"}}) {
        if (e.find(names[0]) < 0 || e.find(names[1]) < 0 || e.find(names[2]) < 0) continue;
        for (int c = 0; c < 3; ++c) {
          rgb[c] = e.find(names[size_t(c)]);
          const PlyType t = e.properties[size_t(rgb[c])].type;
          rgb_scale[c] = t == PlyType::Uint8 || t == PlyType::Int8 ? 255.0f : is_integer(t) ? 65535.0f : 1.0f;
        }
        break;
      }
      if (rgb[0] < 0 && (e.find("red") >= 0 || e.find("r") >= 0 || e.find("green") >= 0 || e.find("g") >= 0)) {
        warnings.add("vertex colours without all of red, green and blue not used");
      }
      if (e.count > UINT32_MAX) throw InputError(name + ": more than 2^32 vertices");
      mesh.positions.reserve(e.count);
      if (nx >= 0) mesh.normals.reserve(e.count);
      if (u >= 0) mesh.uvs.reserve(e.count);
      if (rgb[0] >= 0) mesh.colors.reserve(e.count);
      have_vertices = true;
    } else if (is_face) {
      if (!have_vertices) throw InputError(name + ":" + std::to_string(e.line) + ": faces before the vertices");
      list = e.find("vertex_indices");
      if (list < 0) list = e.find("vertex_index");
      if (list < 0 || !e.properties[size_t(list)].list || !is_integer(e.properties[size_t(list)].type)) {
        throw InputError(name + ":" + std::to_string(e.line) + ": face has no integer list vertex_indices");
      }
      // At least a triangle a face: refused here, before the triangles are read.
      refuse_past_memory(limits, name, e.count, mesh.normals.capacity() > 0, mesh.uvs.capacity() > 0,
                         mesh.colors.capacity() > 0);
      have_faces = true;
    } else {
      warnings.add("element " + in_quotes(e.name) + " ignored");
    }
    if (e.properties.empty()) continue;  // rows of nothing, however many
    row.resize(e.properties.size());
    for (uint64_t r = 0; r < e.count; ++r) {
      if ((r & 0xffff) == 0) throw_if_cancelled(cancel);
      in.begin_row();
      for (size_t k = 0; k < e.properties.size(); ++k) {
        const PlyProperty& p = e.properties[k];
        if (!p.list) {
          row[k] = in.value(p.type, "a row");
          continue;
        }
        const double count = in.value(p.count_type, "a list's count");
        if (count < 0.0) throw in.fail("a list of negative length in element " + in_quotes(e.name));
        const auto n = uint64_t(count);
        if (is_face && int(k) == list) {
          polygon.clear();
          for (uint64_t i = 0; i < n; ++i) {
            const double index = in.value(p.type, "a face");
            if (index < 0.0 || index >= double(mesh.positions.size())) {
              throw in.fail("face " + std::to_string(r) + ": vertex index " + std::to_string((long long)index) +
                            " out of range (" + std::to_string(mesh.positions.size()) + " vertices)");
            }
            polygon.push_back(uint32_t(index));
          }
        } else {
          for (uint64_t i = 0; i < n; ++i) in.value(p.type, "a list");
        }
      }
      if (is_vertex) {
        const Vec3 pos{float(row[size_t(x)]), float(row[size_t(y)]), float(row[size_t(z)])};
        if (!is_finite(pos) || std::max({std::fabs(pos.x), std::fabs(pos.y), std::fabs(pos.z)}) > kMaxCoordinate) {
          throw in.fail("vertex " + std::to_string(r) + " is not finite or lies beyond +-" + kMaxCoordinateText);
        }
        mesh.positions.push_back(pos);
        if (nx >= 0) {
          const Vec3 n{float(row[size_t(nx)]), float(row[size_t(ny)]), float(row[size_t(nz)])};
          mesh.normals.push_back(is_finite(n) ? n : Vec3{0.0f});
        }
        if (u >= 0) {
          const Vec2 t{float(row[size_t(u)]), float(row[size_t(v)])};
          mesh.uvs.push_back(std::isfinite(t.x) && std::isfinite(t.y) ? t : Vec2{});
        }
        if (rgb[0] >= 0) {
          Vec3 c;
          for (int k = 0; k < 3; ++k) {
            const float value = std::clamp(float(row[size_t(rgb[k])]) / rgb_scale[k], 0.0f, 1.0f);
            c[k] = rgb_scale[k] > 1.0f ? srgb_to_linear(value) : value;
          }
          mesh.colors.push_back(is_finite(c) ? c : Vec3{1.0f});
        }
      } else if (is_face) {
        if (polygon.size() < 3) {
          warnings.add("a face with fewer than 3 corners skipped");
        } else if (polygon.size() == 3) {
          mesh.indices.insert(mesh.indices.end(), polygon.begin(), polygon.end());
        } else {
          corners.clear();
          for (uint32_t i : polygon) corners.push_back(mesh.positions[i]);
          triangulate(corners.data(), uint32_t(corners.size()), triangles);
          for (const auto& t : triangles)
            for (uint32_t c : t) mesh.indices.push_back(polygon[c]);
        }
      }
      in.end_row(e.name);
    }
  }
  if (in.remaining() > 0 && !in.ascii()) warnings.add("bytes after the last element ignored");
  if (mesh.indices.empty()) throw InputError(name + ": scene has no triangles");
  if (phases) phases->parse_ms = ms_since(parse_start);
  const auto build_start = Clock::now();
  Scene scene;
  scene.source = name;
  scene.materials.push_back(Material{});
  append_mesh(scene, "ply", mesh, 0);
  scene.finalize();
  if (phases) phases->assembly_ms = ms_since(build_start);
  warnings.flush(name, warn);
  return scene;
}

}  // namespace

Scene load_ply(const std::string& path, const WarningSink& warn, CancelFlag cancel, const LoadLimits& limits,
               LoadPhases* phases) {
  const auto read_start = Clock::now();
  const InputBytes bytes = map_input(path, cancel, limits.max_obj_bytes);
  if (phases) phases->read_ms = ms_since(read_start);
  return load(bytes.view(), path, warn, cancel, limits, phases);
}

Scene load_ply_from_memory(std::string_view bytes, const std::string& name, const WarningSink& warn,
                           const LoadLimits& limits) {
  return load(bytes, name, warn, nullptr, limits, nullptr);
}

}  // namespace tracer
