#include "scene/scene_checksum.hpp"

#include <cstring>
#include <type_traits>
#include <vector>

namespace tracer {

namespace {

class Fnv1a {
 public:
  void bytes(const void* data, size_t n) {
    const auto* p = static_cast<const unsigned char*>(data);
    for (size_t i = 0; i < n; ++i) {
      h_ ^= p[i];
      h_ *= 0x100000001b3ull;
    }
  }
  template <class T>
  void value(const T& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    bytes(&v, sizeof v);
  }
  template <class T, class A>
  void array(const std::vector<T, A>& v) {
    value(uint64_t(v.size()));
    if (!v.empty()) bytes(v.data(), v.size() * sizeof(T));
  }
  uint64_t get() const { return h_; }

 private:
  uint64_t h_ = 0xcbf29ce484222325ull;
};

}  // namespace

uint64_t scene_checksum(const Scene& scene) {
  Fnv1a h;
  h.array(scene.triangles);
  h.array(scene.tri_material);
  h.array(scene.corner_normals);
  h.array(scene.corner_uvs);
  if (!scene.corner_uvs1.empty()) h.array(scene.corner_uvs1);  // scenes without keep their checksums
  if (!scene.corner_colors.empty()) h.array(scene.corner_colors);
  h.value(uint64_t(scene.materials.size()));
  for (const Material& m : scene.materials) {
    for (const Vec3& c : {m.kd, m.ks, m.ke, m.tf}) h.value(c);
    h.value(m.ns);
    h.value(m.ni);
    h.value(m.illum);
    // Each slot's texture; how it addresses it only where that is not the default, so scenes
    // with plain slots keep the checksums they had.
    const auto slot = [&](const TextureSlot& t) {
      h.value(t.texture);
      if (t.uv_set != 0 || !(t.sampler == Sampler{}) || !t.transform.identity()) {
        h.value(t.uv_set);
        h.value(int(t.sampler.wrap_s) | int(t.sampler.wrap_t) << 4 | int(t.sampler.nearest) << 8 |
                int(t.sampler.mipmaps) << 9);
        for (float x : {t.transform.a, t.transform.b, t.transform.c, t.transform.d, t.transform.e, t.transform.f})
          h.value(x);
      }
    };
    slot(m.diffuse_texture);
    slot(m.bump_texture);
    h.value(m.bump_multiplier);
    if (m.normal_texture.present()) {  // glTF's; OBJ scenes keep the checksums they had
      slot(m.normal_texture);
      h.value(m.normal_scale);
    }
    if (m.metallic_roughness) {  // glTF's; OBJ scenes keep the checksums they had
      h.value(m.metallic);
      h.value(m.roughness);
      h.value(m.specular_f0);
      h.value(m.specular_f90);
      slot(m.metallic_roughness_texture);
    }
    for (const TextureSlot* t : {&m.emission_texture, &m.specular_texture, &m.shininess_texture})
      if (t->present()) slot(*t);  // likewise
  }
  h.value(uint64_t(scene.textures.size()));
  for (const Texture& t : scene.textures) {
    h.value(t.width());
    h.value(t.height());
    h.array(t.srgb());
  }
  h.value(uint64_t(scene.lights.size()));
  for (const Light& l : scene.lights) {
    for (const Vec3& c : {l.position, l.normal, l.power}) h.value(c);
    h.value(l.area);
    if (l.kind == LightKind::Spot || l.kind == LightKind::Directional) {  // point and area keep their checksums
      h.value(l.kind);
      h.value(l.cos_outer);
      h.value(l.cos_inner);
    }
  }
  if (scene.instanced()) {  // flat scenes keep the checksums they had
    h.value(uint64_t(scene.meshes.size()));
    for (const Mesh& m : scene.meshes) h.value(m.triangles);
    h.value(uint64_t(scene.instances.size()));
    for (const Instance& in : scene.instances) {
      h.value(in.mesh);
      h.value(in.to_world.m);
    }
  }
  return h.get();
}

uint64_t environment_checksum(const EnvironmentMap& map) {
  Fnv1a h;
  h.value(map.width());
  h.value(map.height());
  h.value(map.rotation_turns());
  h.array(map.texels());
  return h.get();
}

}  // namespace tracer
