// Instances: a mesh (a run of the scene's triangles, in its own space) placed by an affine
// transform, as glTF's nodes place meshes. A scene with instances keeps each mesh once and is
// traced through a two-level tree (a tree per mesh, one over the instances); a scene without
// them is its triangles, in world space.
#pragma once

#include <cstdint>
#include <string>

#include "math/aabb.hpp"
#include "math/affine.hpp"
#include "math/vec.hpp"

namespace tracer {

struct Scene;

// The triangles [first, first + count) of the scene's arrays.
struct TriangleRange {
  uint32_t first = 0, count = 0;
  static TriangleRange all(const Scene& scene);
};

// An affine map in float, rows of [linear | translation], as traversal applies it to rays.
struct Transform {
  float m[3][4] = {{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}};

  static Transform of(const Affine& a) {
    Transform t;
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 4; ++c) t.m[r][c] = float(a.m[r][c]);
    return t;
  }
  Vec3 point(Vec3 p) const {
    return {m[0][0] * p.x + m[0][1] * p.y + m[0][2] * p.z + m[0][3],
            m[1][0] * p.x + m[1][1] * p.y + m[1][2] * p.z + m[1][3],
            m[2][0] * p.x + m[2][1] * p.y + m[2][2] * p.z + m[2][3]};
  }
  Vec3 vector(Vec3 v) const {
    return {m[0][0] * v.x + m[0][1] * v.y + m[0][2] * v.z, m[1][0] * v.x + m[1][1] * v.y + m[1][2] * v.z,
            m[2][0] * v.x + m[2][1] * v.y + m[2][2] * v.z};
  }
  // The transpose of the linear part times v: a normal moved by the inverse transpose, when this
  // is the inverse of the map that moves the points.
  Vec3 transposed(Vec3 v) const {
    return {m[0][0] * v.x + m[1][0] * v.y + m[2][0] * v.z, m[0][1] * v.x + m[1][1] * v.y + m[2][1] * v.z,
            m[0][2] * v.x + m[1][2] * v.y + m[2][2] * v.z};
  }
};

// A mesh: its triangles in the scene's arrays (geomID and primID as in a flat scene) and their box.
struct Mesh {
  std::string name;
  TriangleRange triangles;
  Aabb bounds;            // of its non-degenerate triangles (Scene::finalize)
  bool emissive = false;  // holds a triangle of an emissive material (Scene::finalize)
};

// One placement of a mesh. to_object is to_world's inverse, computed in double.
struct Instance {
  uint32_t mesh = 0;
  Transform to_world, to_object;
  Aabb bounds;           // in world space: the mesh box moved, padded (Scene::finalize)
  bool mirrors = false;  // to_world's determinant is negative: it reverses the triangles' winding

  // A world-space normal of the object-space normal n (unnormalised).
  Vec3 normal(Vec3 n) const { return to_object.transposed(n); }
};

// An instance of `mesh` placed by `world`, which must be invertible; its box is Scene::finalize's.
Instance make_instance(uint32_t mesh, const Affine& world);

}  // namespace tracer
