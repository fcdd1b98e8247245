// The project's own scenes and closed meshes (the default scene, test geometry).
#pragma once

#include <cstdint>
#include <vector>

#include "math/affine.hpp"
#include "scene/scene.hpp"

namespace tracer {

struct IndexedMesh {
  std::vector<Vec3> vertices;
  std::vector<uint32_t> indices;  // three per triangle, counter-clockwise seen from outside
};

// Closed UV sphere with shared vertices (poles are single vertices): 2*slices*(stacks-1) triangles.
IndexedMesh make_uv_sphere(Vec3 center, float radius, int slices, int stacks);

// Closed axis-aligned box: 12 triangles with shared corners.
IndexedMesh make_box(Vec3 lo, Vec3 hi);

// The Cornell box from Cornell's published measurements (graphics.cornell.edu/online/box/data.html),
// scaled from millimetres so the box is 2 units tall: walls, lamp, the short and the tall block,
// and, when sphere_triangles > 0, two spheres of about that many triangles each. It suggests the
// measured camera (eye at z = -800 mm looking down +z, 37.5 degree field of view).
Scene make_cornell_box(int sphere_triangles = 0);

// n placements of a scene of box `bounds` on a square grid along +x and -z, 1.1 times its larger
// horizontal extent apart, each turned about y by its own angle: the instancing benchmarks' layout
// (bench/make_instances.cpp writes it as glTF; tracer bench's instanced scene builds it).
std::vector<Affine> grid_placements(const Aabb& bounds, uint32_t n);

// `scene`'s triangles kept once, as one mesh placed by each of `placements`: an instanced scene.
Scene place_instances(Scene scene, const std::vector<Affine>& placements);

}  // namespace tracer
