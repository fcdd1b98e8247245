#include "importers/obj_parser.hpp"

#include <fast_float/fast_float.h>

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstring>
#include <exception>
#include <limits>
#include <utility>

#include "base/text.hpp"
#include "importers/obj_numbers.hpp"
#include "math/triangulate.hpp"

namespace tracer {

namespace {

// How often the long loops poll the cancel flag: often enough to stop within milliseconds.
constexpr uint64_t kCancelStride = 1 << 16;
// A corner without a texture coordinate or normal.
constexpr int32_t kNone = std::numeric_limits<int32_t>::min();
constexpr int64_t kMaxIndex = std::numeric_limits<int32_t>::max();
// Chunks of at least this many bytes (smaller files are one chunk), and at most this many chunks.
constexpr size_t kMinChunkBytes = size_t(1) << 18;
constexpr size_t kMaxChunks = 64;

constexpr const char* kIndexKinds[3] = {"vertex", "texture coordinate", "normal"};

}  // namespace

// One chunk: its text, what its lines defined, and its faces' corners. Parsed without knowing
// how many vertices came before it, a chunk keeps a positive index as the absolute index it is
// and a negative one relative to its own vertices ("relative" below), and notes the least number
// of earlier vertices (`need`) that makes every index valid; one that mixes the two is parsed
// again once that number is known.
struct ObjGeometry::Chunk {
  enum class Indices : uint8_t { Unknown, Absolute, Relative };
  std::string_view text;
  std::vector<Vec3> v, vn;
  std::vector<Vec2> vt;
  std::vector<int32_t> corner_v, corner_vt, corner_vn;  // vt, vn: empty while no corner has one
  std::vector<uint32_t> face_size;
  std::vector<ObjStatement> statements;  // lines and triangles counted from this chunk's start
  uint64_t lines = 0, triangles = 0;
  int64_t need[3] = {0, 0, 0};
  Indices indices = Indices::Unknown;
  bool has_vt = false, has_vn = false;
  bool reparse = false;
  bool failed = false;
  std::exception_ptr error;

  // `prefix`: the v, vt, vn counts before this chunk when known (indices are then checked and
  // stored absolute), or null. `first_line` numbers lines in messages.
  void parse(const std::string& name, const uint64_t* prefix, uint64_t first_line, CancelFlag cancel);
  void clear() {
    const std::string_view keep = text;
    *this = Chunk{};
    text = keep;
  }

 private:
  void parse_line(std::string_view rest, const std::string& name, const uint64_t* prefix, uint64_t line,
                  uint64_t local_line);
  // The two lines that make most of a file, written plainly (`v x y z`, `f a/b/c ...`): read
  // without tokenising, or false, with nothing changed, for parse_line to read the line.
  bool parse_plain_vertex(const char* p, const char* end, std::vector<Vec3>& out);
  bool parse_plain_vt(const char* p, const char* end);
  bool parse_plain_face(const char* p, const char* end, const std::string& name, const uint64_t* prefix, uint64_t line);
  int32_t index(int slot, long long value, const std::string& name, const uint64_t* prefix, uint64_t line);
  void set_indices(Indices kind) {
    if (indices == Indices::Unknown) indices = kind;
    if (indices != kind) reparse = true;
  }
};

void ObjGeometry::Chunk::parse(const std::string& name, const uint64_t* prefix, uint64_t first_line,
                               CancelFlag cancel) {
  if (prefix) indices = Indices::Absolute;
  const char* p = text.data();
  const char* const end = p + text.size();
  uint64_t local = 0;
  // Lines end at "\n", "\r\n" or a lone "\r" (as for_each_line splits them). The next '\n' is
  // searched for once and kept, so a file of lone-'\r' lines is not searched to its end per line.
  const char* nl = p;
  bool nl_known = false;
  while (p < end) {
    if (!nl_known || nl < p) {
      nl = static_cast<const char*>(std::memchr(p, '\n', size_t(end - p)));
      if (!nl) nl = end;
      nl_known = true;
    }
    const char* eol = nl;
    if (const void* cr = std::memchr(p, '\r', size_t(nl - p))) eol = static_cast<const char*>(cr);
    ++local;
    if (local % kCancelStride == 0) throw_if_cancelled(cancel);
    const uint64_t line = first_line + local - 1;
    const char* q = p;
    while (q < eol && is_blank(*q)) ++q;
    const bool plain =
        eol - q > 2 && ((q[0] == 'v' && is_blank(q[1]) && parse_plain_vertex(q + 2, eol, v)) ||
                        (q[0] == 'v' && q[1] == 'n' && is_blank(q[2]) && parse_plain_vertex(q + 3, eol, vn)) ||
                        (q[0] == 'v' && q[1] == 't' && is_blank(q[2]) && parse_plain_vt(q + 3, eol)) ||
                        (q[0] == 'f' && is_blank(q[1]) && parse_plain_face(q + 2, eol, name, prefix, line)));
    if (!plain) parse_line(std::string_view(p, size_t(eol - p)), name, prefix, line, local);
    p = eol;
    if (p < end) p += (*p == '\r' && p + 1 < end && p[1] == '\n') ? 2 : 1;
  }
  lines = local;
}

int32_t ObjGeometry::Chunk::index(int slot, long long value, const std::string& name, const uint64_t* prefix,
                                  uint64_t line) {
  const size_t defined = slot == 0 ? v.size() : (slot == 1 ? vt.size() : vn.size());
  if (prefix) {
    const auto count = static_cast<long long>(prefix[slot] + defined);
    if (value == 0 || value > count || value < -count) {
      fail_at(name, line,
              std::string(kIndexKinds[slot]) + " index " + std::to_string(value) + " out of range (" +
                  std::to_string(count) + " defined so far)");
    }
    const long long absolute = value > 0 ? value - 1 : count + value;
    if (absolute > kMaxIndex) fail_at(name, line, "more vertices than tracer can index (2^31)");
    return static_cast<int32_t>(absolute);
  }
  if (value == 0) fail_at(name, line, std::string(kIndexKinds[slot]) + " index 0");
  const auto here = static_cast<long long>(defined);
  if (value > 0) {
    set_indices(Indices::Absolute);
    if (value - 1 > kMaxIndex) fail_at(name, line, "index beyond 2^31");
    need[slot] = std::max<int64_t>(need[slot], value - here);
    return static_cast<int32_t>(value - 1);
  }
  set_indices(Indices::Relative);
  const long long relative = here + value;  // from this chunk's first vertex; negative: earlier
  if (relative < -kMaxIndex) fail_at(name, line, "index beyond 2^31");
  need[slot] = std::max<int64_t>(need[slot], -relative);
  return static_cast<int32_t>(relative);
}

bool ObjGeometry::Chunk::parse_plain_vertex(const char* p, const char* end, std::vector<Vec3>& out) {
  float xyz[3];
  for (float& c : xyz) {
    while (p < end && is_blank(*p)) ++p;
    if (!parse_plain_decimal(p, end, c)) return false;
  }
  while (p < end && is_blank(*p)) ++p;
  if (p != end) return false;  // a fourth number (w, or a colour): parse_line reads it
  out.push_back({xyz[0], xyz[1], xyz[2]});
  return true;
}

bool ObjGeometry::Chunk::parse_plain_vt(const char* p, const char* end) {
  float uvw[3] = {0.0f, 0.0f, 0.0f};
  int n = 0;
  for (;;) {
    while (p < end && is_blank(*p)) ++p;
    if (p == end) break;
    if (n == 3 || !parse_plain_decimal(p, end, uvw[n])) return false;
    ++n;
  }
  if (n == 0) return false;
  vt.push_back({uvw[0], uvw[1]});
  return true;
}

bool ObjGeometry::Chunk::parse_plain_face(const char* p, const char* end, const std::string& name,
                                          const uint64_t* prefix, uint64_t line) {
  constexpr int kMaxCorners = 8;
  long long idx[kMaxCorners][3];
  bool present[3] = {true, false, false};  // the same slots for every corner, or parse_line reads it
  int corners = 0;
  for (;;) {
    while (p < end && is_blank(*p)) ++p;
    if (p == end) break;
    if (corners == kMaxCorners || !parse_plain_index(p, end, idx[corners][0])) return false;
    bool has[3] = {true, false, false};
    if (p < end && *p == '/') {
      ++p;
      if (p < end && *p != '/') {
        if (!parse_plain_index(p, end, idx[corners][1])) return false;
        has[1] = true;
      }
      if (p < end && *p == '/') {
        ++p;
        if (!parse_plain_index(p, end, idx[corners][2])) return false;
        has[2] = true;
      }
    }
    if (p < end && !is_blank(*p)) return false;
    if (corners == 0) present[1] = has[1], present[2] = has[2];
    if (has[1] != present[1] || has[2] != present[2]) return false;
    ++corners;
  }
  if (corners < 3) return false;
  // Committed: the indices checked in order, as parse_line would, so the first bad one throws.
  if (present[1] && !has_vt) has_vt = true, corner_vt.assign(corner_v.size(), kNone);
  if (present[2] && !has_vn) has_vn = true, corner_vn.assign(corner_v.size(), kNone);
  for (int k = 0; k < corners; ++k) {
    const int32_t iv = index(0, idx[k][0], name, prefix, line);
    const int32_t it = present[1] ? index(1, idx[k][1], name, prefix, line) : kNone;
    const int32_t in = present[2] ? index(2, idx[k][2], name, prefix, line) : kNone;
    corner_v.push_back(iv);
    if (has_vt) corner_vt.push_back(it);
    if (has_vn) corner_vn.push_back(in);
  }
  face_size.push_back(uint32_t(corners));
  triangles += uint64_t(corners - 2);
  return true;
}

void ObjGeometry::Chunk::parse_line(std::string_view rest, const std::string& name, const uint64_t* prefix,
                                    uint64_t line, uint64_t local_line) {
  rest = trim(rest);
  if (rest.empty() || rest.front() == '#') return;
  // A comment after the values (`v 1 2 3 # note`), as tinyobjloader reads a `v` line; a `#`
  // glued to a value stays part of it (`3#x` is no index).
  for (size_t at = rest.find('#'); at != std::string_view::npos; at = rest.find('#', at + 1)) {
    if (is_blank(rest[at - 1])) {
      rest = trim(rest.substr(0, at));
      break;
    }
  }
  const std::string_view keyword = next_token(rest);
  if (keyword == "v" || keyword == "vn" || keyword == "vt") {
    const size_t needed = keyword == "vt" ? 1 : 3;
    float xyz[3] = {0.0f, 0.0f, 0.0f};
    size_t n = 0;
    for (std::string_view tok = next_token(rest); !tok.empty(); tok = next_token(rest), ++n) {
      const float f = parse_coordinate(tok, name, line);
      if (n < 3) xyz[n] = f;
    }
    if (n < needed) {
      fail_at(name, line,
              "'" + std::string(keyword) + "' needs " + std::to_string(needed) + " numbers, got " + std::to_string(n));
    }
    if (keyword == "v") {
      v.push_back({xyz[0], xyz[1], xyz[2]});
    } else if (keyword == "vn") {
      vn.push_back({xyz[0], xyz[1], xyz[2]});
    } else {
      vt.push_back({xyz[0], xyz[1]});
    }
  } else if (keyword == "f" || keyword == "l" || keyword == "p") {
    // Lines and points make no triangles, but their indices are checked as a face's are.
    const bool face = keyword == "f";
    uint32_t corners = 0;
    for (std::string_view tok = next_token(rest); !tok.empty(); tok = next_token(rest), ++corners) {
      // v, v/vt, v//vn or v/vt/vn
      int32_t idx[3] = {kNone, kNone, kNone};
      std::string_view parts = tok;
      for (int slot = 0; slot < 3 && !parts.empty(); ++slot) {
        const size_t slash = parts.find('/');
        const std::string_view part = parts.substr(0, slash);
        parts.remove_prefix(slash == std::string_view::npos ? parts.size() : slash + 1);
        if (part.empty() && slot == 1) continue;
        idx[slot] = index(slot, parse_index(part, tok, name, line), name, prefix, line);
      }
      if (!face) continue;
      if (idx[1] != kNone && !has_vt) has_vt = true, corner_vt.assign(corner_v.size(), kNone);
      if (idx[2] != kNone && !has_vn) has_vn = true, corner_vn.assign(corner_v.size(), kNone);
      corner_v.push_back(idx[0]);
      if (has_vt) corner_vt.push_back(idx[1]);
      if (has_vn) corner_vn.push_back(idx[2]);
    }
    if (!face) return;
    if (corners < 3) fail_at(name, line, "face needs at least 3 vertices, got " + std::to_string(corners));
    face_size.push_back(corners);
    triangles += corners - 2;
  } else if (keyword == "usemtl" || keyword == "g" || keyword == "o" || keyword == "mtllib") {
    ObjStatement s;
    s.triangle = triangles;
    s.line = local_line;
    if (keyword == "usemtl") {
      s.kind = ObjStatement::Kind::UseMtl;
      s.names.emplace_back(next_token(rest));
    } else if (keyword == "mtllib") {
      s.kind = ObjStatement::Kind::MtlLib;
      for (std::string_view tok = next_token(rest); !tok.empty(); tok = next_token(rest)) s.names.emplace_back(tok);
    } else {  // a group or object: its name is the rest of the line, blanks between words made one space
      s.kind = ObjStatement::Kind::Group;
      std::string group;
      for (std::string_view tok = next_token(rest); !tok.empty(); tok = next_token(rest)) {
        if (!group.empty()) group += ' ';
        group += tok;
      }
      s.names.push_back(std::move(group));
    }
    statements.push_back(std::move(s));
  }
  // Other statements (s, vp, curves, tags) do not make triangles and are skipped.
}

ObjGeometry::ObjGeometry() = default;
ObjGeometry::~ObjGeometry() = default;
ObjGeometry::ObjGeometry(ObjGeometry&&) noexcept = default;
ObjGeometry& ObjGeometry::operator=(ObjGeometry&&) noexcept = default;

ObjGeometry ObjGeometry::parse(std::string_view text, const std::string& name, const ForEach& for_each,
                               CancelFlag cancel, size_t chunk_bytes) {
  ObjGeometry g;
  g.name_ = name;
  // Chunks end just after a '\n', so no line (nor a "\r\n") straddles two.
  const size_t step = chunk_bytes ? chunk_bytes : std::max(kMinChunkBytes, text.size() / kMaxChunks + 1);
  for (size_t start = 0; start < text.size();) {
    const size_t nl = start + step - 1 < text.size() ? text.find('\n', start + step - 1) : std::string_view::npos;
    const size_t end = nl == std::string_view::npos ? text.size() : nl + 1;
    g.chunks_.emplace_back().text = text.substr(start, end - start);
    start = end;
  }
  static constexpr uint64_t kNoneBefore[3] = {0, 0, 0};
  for_each(g.chunks_.size(), [&](size_t i) {
    Chunk& c = g.chunks_[i];
    try {
      c.parse(name, i == 0 ? kNoneBefore : nullptr, 1, cancel);
    } catch (const InputError&) {
      c.failed = true;
    } catch (...) {
      c.error = std::current_exception();
    }
  });
  for (const Chunk& c : g.chunks_) {
    if (c.error) std::rethrow_exception(c.error);
  }
  // Every index must reach no further back than the vertices before its chunk.
  bool valid = true;
  uint64_t before[3] = {0, 0, 0};
  for (const Chunk& c : g.chunks_) {
    valid = valid && !c.failed;
    for (int k = 0; k < 3; ++k) valid = valid && c.need[k] <= static_cast<int64_t>(before[k]);
    before[0] += c.v.size(), before[1] += c.vt.size(), before[2] += c.vn.size();
  }
  if (!valid) {  // the first error in file order, with its line: one chunk, from the start
    g.chunks_.assign(1, Chunk{});
    g.chunks_[0].text = text;
    g.chunks_[0].parse(name, kNoneBefore, 1, cancel);
  }
  uint64_t lines = 0;
  for (Chunk& c : g.chunks_) {
    for (ObjStatement& s : c.statements) {
      s.triangle += g.triangles_;
      s.line += lines;
      g.statements_.push_back(std::move(s));
    }
    c.statements.clear();
    lines += c.lines;
    g.triangles_ += c.triangles;
    g.counts_[0] += c.v.size(), g.counts_[1] += c.vt.size(), g.counts_[2] += c.vn.size();
    g.any_uv_ = g.any_uv_ || c.has_vt;
    g.any_normal_ = g.any_normal_ || c.has_vn;
  }
  if (g.triangles_ >= kInvalidIndex) throw InputError(name + ": more triangles than tracer can index (2^32 - 1)");
  return g;
}

void ObjGeometry::assemble(Scene& scene, const std::vector<TriangleRun>& runs,
                           const std::vector<uint32_t>& geometry_first, const ForEach& for_each, CancelFlag cancel) {
  const size_t n = chunks_.size();
  std::vector<std::array<uint64_t, 3>> before(n);  // v, vt, vn before each chunk
  std::vector<uint64_t> triangles_before(n);
  for (size_t i = 1; i < n; ++i) {
    const Chunk& c = chunks_[i - 1];
    before[i] = {before[i - 1][0] + c.v.size(), before[i - 1][1] + c.vt.size(), before[i - 1][2] + c.vn.size()};
    triangles_before[i] = triangles_before[i - 1] + c.triangles;
  }
  // 1. Every chunk's vertices into one array each (a face may name any earlier chunk's).
  std::vector<Vec3> positions(counts_[0]), normals(counts_[2]);
  std::vector<Vec2> uvs(counts_[1]);
  for_each(n, [&](size_t i) {
    Chunk& c = chunks_[i];
    if (c.reparse) {  // mixes absolute and relative indices: read again, its prefix now known
      c.clear();
      c.parse(name_, before[i].data(), 1, cancel);
    }
    std::copy(c.v.begin(), c.v.end(), positions.begin() + std::ptrdiff_t(before[i][0]));
    std::copy(c.vt.begin(), c.vt.end(), uvs.begin() + std::ptrdiff_t(before[i][1]));
    std::copy(c.vn.begin(), c.vn.end(), normals.begin() + std::ptrdiff_t(before[i][2]));
    std::vector<Vec3>().swap(c.v);
    std::vector<Vec2>().swap(c.vt);
    std::vector<Vec3>().swap(c.vn);
  });
  throw_if_cancelled(cancel);

  // 2. Every chunk's faces into triangles, at the place its triangles have in the file.
  scene.vertex_count = counts_[0];
  scene.triangles.resize(triangles_);
  scene.tri_geom.resize(triangles_);
  scene.tri_prim.resize(triangles_);
  scene.tri_material.resize(triangles_);
  if (any_normal_) scene.corner_normals.assign(3 * triangles_, Vec3{0.0f});
  if (any_uv_) scene.corner_uvs.assign(3 * triangles_, Vec2{});
  for_each(n, [&](size_t i) {
    Chunk& c = chunks_[i];
    const bool relative = c.indices == Chunk::Indices::Relative;
    const auto global = [&](int slot, int32_t local) -> size_t {
      return size_t(relative ? int64_t(before[i][size_t(slot)]) + local : local);
    };
    uint64_t t = triangles_before[i];
    size_t run = size_t(std::upper_bound(runs.begin(), runs.end(), t,
                                         [](uint64_t x, const TriangleRun& r) { return x < r.first; }) -
                        runs.begin()) -
                 1;
    std::vector<Vec3> corners;
    std::vector<std::array<uint32_t, 3>> tris;
    size_t first_corner = 0;
    for (size_t f = 0; f < c.face_size.size(); ++f) {
      if (f % kCancelStride == kCancelStride - 1) throw_if_cancelled(cancel);
      const uint32_t size = c.face_size[f];
      corners.resize(size);
      for (uint32_t k = 0; k < size; ++k) corners[k] = positions[global(0, c.corner_v[first_corner + k])];
      triangulate(corners.data(), size, tris);
      for (const std::array<uint32_t, 3>& tri : tris) {
        while (run + 1 < runs.size() && runs[run + 1].first <= t) ++run;
        scene.triangles[t] = {corners[tri[0]], corners[tri[1]], corners[tri[2]]};
        scene.tri_material[t] = runs[run].material;
        scene.tri_geom[t] = runs[run].geometry;
        scene.tri_prim[t] = static_cast<uint32_t>(t - geometry_first[runs[run].geometry]);
        for (int k = 0; k < 3; ++k) {
          const size_t corner = first_corner + tri[size_t(k)];
          if (c.has_vn && c.corner_vn[corner] != kNone)
            scene.corner_normals[3 * t + size_t(k)] = normals[global(2, c.corner_vn[corner])];
          if (c.has_vt && c.corner_vt[corner] != kNone)
            scene.corner_uvs[3 * t + size_t(k)] = uvs[global(1, c.corner_vt[corner])];
        }
        ++t;
      }
      first_corner += size;
    }
    c = Chunk{};
  });
  throw_if_cancelled(cancel);
  chunks_.clear();
}

}  // namespace tracer
