// OBJ geometry in one pass over the bytes, in parallel over chunks split at line ends (as
// rapidobj does): each chunk parses and checks its own lines; what crosses chunks (a face's
// indices into earlier chunks, negative indices, the `usemtl` and `g`/`o` state) is resolved once
// every chunk's counts are known. Numbers are read by fast_float (correctly rounded).
//
// Errors name the file and line. A chunk that meets anything wrong, or whose indices turn out to
// reach past what came before it, sends the whole text through the same parser once more as a
// single chunk from the first line, which stops at the first error in file order with its exact
// message: the error path is sequential, the accepted path parallel, and both are one parser.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include "base/errors.hpp"
#include "importers/load_limits.hpp"
#include "math/vec.hpp"
#include "scene/scene.hpp"

namespace tracer {

// A statement that sets state for the faces after it.
struct ObjStatement {
  enum class Kind : uint8_t { UseMtl, Group, MtlLib };
  Kind kind = Kind::Group;
  uint64_t triangle = 0;           // triangles before it in the file
  uint64_t line = 0;               // its line, from 1
  std::vector<std::string> names;  // usemtl: the material; g/o: the name; mtllib: the files
};

// Which material and geometry the triangles from `first` on take, up to the next run's first.
struct TriangleRun {
  uint64_t first = 0;
  uint32_t material = 0;
  uint32_t geometry = 0;
};

class ObjGeometry {
 public:
  // Parses and checks `text` (the OBJ, its byte-order mark already removed); `name` stands for the
  // file in messages. Throws InputError("name:line: ..."), or Cancelled. `chunk_bytes` 0 picks the
  // chunk size from the text's size; a small value (tests, fuzzing) forces many chunks.
  static ObjGeometry parse(std::string_view text, const std::string& name, const ForEach& for_each, CancelFlag cancel,
                           size_t chunk_bytes = 0);

  // The `usemtl`, `g`/`o` and `mtllib` statements, in file order.
  const std::vector<ObjStatement>& statements() const { return statements_; }
  uint64_t triangle_count() const { return triangles_; }
  uint64_t vertex_count() const { return counts_[0]; }
  bool any_normal() const { return any_normal_; }  // the scene gets corner normals
  bool any_uv() const { return any_uv_; }          // and corner uvs

  // Writes the triangles into `scene` (triangles, tri_geom, tri_prim, tri_material, and
  // corner_normals / corner_uvs where the file gives any): faces of more than three corners
  // triangulated, each triangle's material and geometry from `runs` (sorted by first, the first at
  // 0), its primID counted from `geometry_first[geometry]`. Consumes the parsed chunks.
  void assemble(Scene& scene, const std::vector<TriangleRun>& runs, const std::vector<uint32_t>& geometry_first,
                const ForEach& for_each, CancelFlag cancel);

  // One chunk's parse; public only so the parser's helpers in the .cpp can name it.
  struct Chunk;
  ObjGeometry();
  ~ObjGeometry();
  ObjGeometry(ObjGeometry&&) noexcept;
  ObjGeometry& operator=(ObjGeometry&&) noexcept;

 private:
  std::string name_;
  std::vector<Chunk> chunks_;
  std::vector<ObjStatement> statements_;
  uint64_t counts_[3] = {0, 0, 0};  // v, vt, vn in the file
  uint64_t triangles_ = 0;
  bool any_uv_ = false, any_normal_ = false;
};

}  // namespace tracer
