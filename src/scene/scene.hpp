// The scene: triangles in flat arrays (what every accelerator reads), their materials, lights and
// an optional camera the scene suggests.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "base/huge_pages.hpp"
#include "base/invalid_index.hpp"
#include "math/aabb.hpp"
#include "math/vec.hpp"
#include "scene/emitters.hpp"
#include "scene/environment_map.hpp"
#include "scene/instances.hpp"
#include "scene/texture.hpp"

namespace tracer {

struct Triangle {
  Vec3 v0, v1, v2;

  Aabb bounds() const {
    Aabb b;
    b.extend(v0);
    b.extend(v1);
    b.extend(v2);
    return b;
  }
  Vec3 centroid() const { return (v0 + v1 + v2) * (1.0f / 3.0f); }
  // Unnormalised geometric normal, (v1-v0) x (v2-v0): counter-clockwise faces point at the viewer.
  Vec3 normal() const { return cross(v1 - v0, v2 - v0); }
  // Zero area in exact arithmetic (collinear or coincident vertices): such a triangle never hits.
  bool degenerate() const;
};

// How a material scatters light: MTL's diffuse-and-glossy, mirror and dielectric illumination
// models, or glTF's metallic-roughness BRDF. The study's ao workload shades every surface as
// diffuse.
enum class SurfaceKind { Diffuse, Mirror, Dielectric, MetallicRoughness };

// A surface's material. OBJ: Kd diffuse, Ks specular, Ns specular exponent, Ke emission, Ni index
// of refraction, Tf transmission filter, illum the MTL illumination model. glTF's metallic-
// roughness (metallic_roughness set): kd is the base colour, `metallic` and `roughness` the
// factors, specular_f0 / specular_f90 the dielectric's Fresnel (docs/FORMATS.md has the mapping).
struct Material {
  std::string name = "default";
  Vec3 kd{0.7f};
  Vec3 ks{0.0f};
  Vec3 ke{0.0f};
  Vec3 tf{1.0f};
  float ns = 0.0f;
  float ni = 1.0f;
  int illum = 2;
  // map_Kd, glTF's baseColorTexture: where present it replaces Kd (the exporters' convention:
  // Sponza's Kd is its texture's mean, so a product would darken it twice).
  TextureSlot diffuse_texture;
  // map_bump / bump: a height map whose values in [0, 1] times bump_multiplier (-bm) displace the
  // surface along its normal, in scene units.
  TextureSlot bump_texture;
  float bump_multiplier = 1.0f;
  // glTF's normalTexture: a tangent-space normal map (its bytes as data, x along +u, y along +v),
  // its x and y scaled by normal_scale.
  TextureSlot normal_texture;
  float normal_scale = 1.0f;
  bool metallic_roughness = false;
  float metallic = 0.0f, roughness = 1.0f;
  Vec3 specular_f0{0.04f};
  float specular_f90 = 1.0f;
  // glTF's metallicRoughnessTexture: its blue channel scales `metallic`, its green `roughness`.
  TextureSlot metallic_roughness_texture;
  // glTF's emissiveTexture, MTL's map_Ke: the emission `ke` times its texel (scene/emission.hpp).
  TextureSlot emission_texture;
  // MTL's map_Ks (its texel times Ks) and map_Ns (the mean of its channels, as data, times Ns).
  TextureSlot specular_texture, shininess_texture;
  // Every slot, for what treats them alike (the importers' index remapping and checks).
  std::array<TextureSlot*, 7> slots() {
    return {&diffuse_texture,  &bump_texture,     &normal_texture,   &metallic_roughness_texture,
            &emission_texture, &specular_texture, &shininess_texture};
  }
  std::array<const TextureSlot*, 7> slots() const {
    return {&diffuse_texture,  &bump_texture,     &normal_texture,   &metallic_roughness_texture,
            &emission_texture, &specular_texture, &shininess_texture};
  }
  bool emissive() const { return ke.x > 0.0f || ke.y > 0.0f || ke.z > 0.0f; }
  // illum 3 and 5 (ray-traced reflection) are mirrors weighted by Ks; 4, 6, 7 and 9 (ray-traced
  // refraction) are dielectrics of index Ni whose transmission Tf filters; the rest diffuse, or
  // metallic-roughness.
  SurfaceKind surface() const {
    if (illum == 3 || illum == 5) return SurfaceKind::Mirror;
    if ((illum == 4 || illum == 6 || illum == 7 || illum == 9) && ni > 0.0f) return SurfaceKind::Dielectric;
    return metallic_roughness ? SurfaceKind::MetallicRoughness : SurfaceKind::Diffuse;
  }
};

// An area light is approximated by its area-weighted centroid (one shadow ray per light, as in the
// study); `power` is Ke times area. A point light has a zero normal and `power` is its intensity.
// A lamp: a point light (--light, glTF's point), a spot (glTF's: a point whose intensity falls
// off between two cones about `normal`), a directional light (glTF's: parallel light travelling
// along `normal` from beyond the scene), or an area light's centroid (an emissive surface, for
// the study's one shadow ray per light; path tracing samples its triangles instead).
enum class LightKind : uint8_t { Point, Spot, Directional, Area };

struct Light {
  Vec3 position;
  Vec3 normal;        // area: the emitting side's normal; spot: the cone's axis; directional: where the light travels
  Vec3 power;         // point, spot: radiant intensity (W/sr); directional: irradiance (W/m^2); area: Ke x area
  float area = 0.0f;  // emitting area (area lights)
  float cos_outer = 0.0f;           // spot: the cosines of its outer and inner cone half-angles
  float cos_inner = 1.0f;           //
  uint32_t geomID = kInvalidIndex;  // the emitting geometry, or kInvalidIndex for a lamp of no surface
  uint32_t inst = kInvalidIndex;    // the instance placing it (instanced scenes)
  LightKind kind = LightKind::Point;
  bool is_point() const { return kind == LightKind::Point; }
  // A point, spot or directional light: one direction from each shading point, which only
  // next-event estimation finds (no ray hits it).
  bool is_delta() const { return kind != LightKind::Area; }
  // glTF's spot falloff (KHR_lights_punctual): a smooth square ramp in the cosine between the two
  // cones, for `cos_axis` the cosine between the axis and the direction to the lit point.
  float spot_falloff(float cos_axis) const {
    const float scale = 1.0f / std::max(1e-3f, cos_inner - cos_outer);
    const float t = std::clamp((cos_axis - cos_outer) * scale, 0.0f, 1.0f);
    return t * t;
  }
};

// One OBJ group/object: geomID is its index, primID counts triangles from `first_triangle`.
struct Geometry {
  std::string name;
  uint32_t first_triangle = 0;
  uint32_t triangle_count = 0;
};

struct CameraSpec {
  Vec3 eye, look, up{0.0f, 1.0f, 0.0f};
  float fov_degrees = 0.0f;
  // A thin lens (depth of field): its radius in scene units (0: a pinhole, everything sharp) and
  // the distance along the view direction of the plane in focus (0: the look-at point's).
  float lens_radius = 0.0f;
  float focus_distance = 0.0f;
};

struct Scene {
  std::string source;  // file path or built-in name
  LargeVector<Triangle> triangles;
  LargeVector<uint32_t> tri_geom;      // geomID per triangle
  LargeVector<uint32_t> tri_prim;      // primID per triangle
  LargeVector<uint32_t> tri_material;  // index into materials
  // Shading normals from the file's `vn`, three per triangle (corner order), or empty when it has
  // none; zero at the corners of faces that give none. The ao workload shades with the geometric
  // normal; whitted interpolates these.
  LargeVector<Vec3> corner_normals;
  // Texture coordinates from the file's `vt` (glTF's TEXCOORD_0), three per triangle, or empty
  // when it has none; corner_uvs1 the second set (TEXCOORD_1), read by slots whose uv_set is 1.
  LargeVector<Vec2> corner_uvs;
  LargeVector<Vec2> corner_uvs1;
  // Vertex colours (glTF's COLOR_0, PLY's red/green/blue), linear, three per triangle, or empty
  // when no mesh has them (white where one lacks them): they multiply the diffuse or base colour.
  LargeVector<Vec3> corner_colors;
  std::vector<Texture> textures;
  std::vector<Geometry> geometries;
  std::vector<Material> materials;
  std::vector<Light> lights;
  Emitters emitters;               // the emissive triangles, for the path integrator's light sampling
  EnvironmentMap environment_map;  // --env-map: the light from beyond the scene, or empty
  size_t vertex_count = 0;
  size_t degenerate_count = 0;
  Aabb bounds;
  std::optional<CameraSpec> camera;  // a camera the scene itself suggests (the built-in box)
  std::vector<CameraSpec> cameras;   // the cameras the file places (glTF), in node order

  // Instances (glTF's nodes placing one mesh several times): each mesh's triangles once, in its
  // own space, and the instances that place them. Empty: the triangles are the world.
  std::vector<Mesh> meshes;
  std::vector<Instance> instances;

  size_t size() const { return triangles.size(); }  // unique triangles
  bool instanced() const { return !instances.empty(); }
  // The triangles the instances place (each mesh's count once per instance); size() when flat.
  uint64_t instanced_size() const;
  // The intensity of a point light when none is given (--light, a view's light): (diagonal / 2)^2.
  float default_light_intensity() const {
    const float diag = length(bounds.extent());
    return 0.25f * diag * diag;
  }
  // Triangle `tri` where instance `inst` places it; as stored when inst is kInvalidIndex (a flat
  // scene's hits).
  Triangle world_triangle(uint32_t tri, uint32_t inst) const {
    const Triangle& t = triangles[tri];
    if (inst == kInvalidIndex) return t;
    const Transform& m = instances[inst].to_world;
    return {m.point(t.v0), m.point(t.v1), m.point(t.v2)};
  }
  // The geometric normal (unnormalised) of `placed`, world_triangle(tri, inst), on its front side:
  // a mirroring instance reverses the winding (as append_mesh reverses a mirrored mesh's corners).
  Vec3 face_normal(const Triangle& placed, uint32_t inst) const {
    const Vec3 n = placed.normal();
    return inst != kInvalidIndex && instances[inst].mirrors ? -n : n;
  }
  // Appends a geometry from an indexed mesh; material is an index into `materials`.
  void add_mesh(const std::string& name, const std::vector<Vec3>& vertices, const std::vector<uint32_t>& indices,
                uint32_t material);
  // The bytes its arrays and textures hold (an estimate of what it occupies).
  uint64_t memory_bytes() const;
  // Per triangle: its corners, ids and material, and its corners' normals and texture coordinates
  // (of `uv_sets` sets) and colours where the scene has them.
  static constexpr uint64_t bytes_per_triangle(bool normals, int uv_sets, bool colors = false) {
    return sizeof(Triangle) + 3 * sizeof(uint32_t) + (normals ? 3 * sizeof(Vec3) : 0) +
           uint64_t(uv_sets) * 3 * sizeof(Vec2) + (colors ? 3 * sizeof(Vec3) : 0);
  }
  // Recomputes bounds, degenerate count, the area lights and the emitters from emissive materials
  // (each instance of an emissive mesh its own lights).
  void finalize();
};

inline TriangleRange TriangleRange::all(const Scene& scene) { return {0, uint32_t(scene.size())}; }

}  // namespace tracer
