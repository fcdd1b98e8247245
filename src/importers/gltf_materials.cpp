#include "importers/gltf_materials.hpp"

#include <algorithm>
#include <cmath>
#include <optional>

#include "base/text.hpp"
#include "importers/texture_batch.hpp"
#include "scene/value_limits.hpp"

namespace tracer::gltf {

namespace fs = std::filesystem;
namespace tg = tinygltf;

uint32_t Materials::material(int index, Scene& scene) {
  if (index >= 0 && size_t(index) >= model_.materials.size()) {
    throw error("material " + std::to_string(index) + " does not exist (the file has " +
                std::to_string(model_.materials.size()) + ")");
  }
  auto [it, fresh] = materials_.try_emplace(index, uint32_t(scene.materials.size()));
  if (!fresh) return it->second;
  if (index < 0) {
    scene.materials.push_back(Material{});
    return it->second;
  }
  scene.materials.push_back(map_material(model_.materials[size_t(index)], index));
  return it->second;
}

// docs/FORMATS.md: how glTF's metallic-roughness model becomes tracer's.
Material Materials::map_material(const tg::Material& g, int index) {
  Material mat;
  mat.name = g.name.empty() ? "material " + std::to_string(index) : g.name;
  const tg::PbrMetallicRoughness& pbr = g.pbrMetallicRoughness;
  const Vec3 base = vec3_of(pbr.baseColorFactor, Vec3{1.0f});
  const float metallic = std::clamp(float(pbr.metallicFactor), 0.0f, 1.0f);
  const float roughness = std::clamp(float(pbr.roughnessFactor), 0.0f, 1.0f);
  if (!is_finite(base) || !std::isfinite(pbr.metallicFactor) || !std::isfinite(pbr.roughnessFactor)) {
    throw error("material " + in_quotes(mat.name) + " has a non-finite factor");
  }
  if (g.alphaMode != "OPAQUE" || (pbr.baseColorFactor.size() == 4 && pbr.baseColorFactor[3] < 1.0)) {
    warnings_.add("alpha (alphaMode " + g.alphaMode + ", base colour alpha) not rendered: surfaces are opaque");
  }
  const tg::Value* strength = extension(g.extensions, "KHR_materials_emissive_strength");
  const double emissive_strength = number(strength, "emissiveStrength", 1.0);
  if (g.emissiveFactor.size() >= 3) {
    const double brightest =
        std::max({g.emissiveFactor[0], g.emissiveFactor[1], g.emissiveFactor[2]}) * emissive_strength;
    if (brightest > kMaxEmission) {
      throw error("material " + in_quotes(mat.name) + ": emission " + format_number(brightest) +
                  " (emissiveFactor x emissiveStrength) above " + format_number(kMaxEmission) +
                  ", the limit of emitted radiance in every format (MTL's Ke too)");
    }
    mat.ke = {float(g.emissiveFactor[0] * emissive_strength), float(g.emissiveFactor[1] * emissive_strength),
              float(g.emissiveFactor[2] * emissive_strength)};
  }
  const tg::Value* transmission = extension(g.extensions, "KHR_materials_transmission");
  const float transmitted = float(number(transmission, "transmissionFactor", 0.0));
  const float ior = float(number(extension(g.extensions, "KHR_materials_ior"), "ior", 1.5));
  const tg::Value* specular = extension(g.extensions, "KHR_materials_specular");
  const float specular_factor = float(number(specular, "specularFactor", 1.0));
  Vec3 specular_colour{1.0f};
  if (specular && specular->IsObject() && specular->Has("specularColorFactor")) {
    const tg::Value& c = specular->Get("specularColorFactor");
    if (c.IsArray() && c.ArrayLen() == 3) {
      specular_colour = {float(c.Get(0).GetNumberAsDouble()), float(c.Get(1).GetNumberAsDouble()),
                         float(c.Get(2).GetNumberAsDouble())};
    }
  }
  if (!is_finite(mat.ke) || !std::isfinite(transmitted) || !std::isfinite(ior) || !std::isfinite(specular_factor) ||
      !is_finite(specular_colour) || mat.ke.x < 0.0f || mat.ke.y < 0.0f || mat.ke.z < 0.0f) {
    throw error("material " + in_quotes(mat.name) + " has a non-finite or negative extension value");
  }

  // The dielectric reflectance at normal incidence: ((ior - 1) / (ior + 1))^2, 0.04 at 1.5.
  const float f0_ior = ior >= 1.0f ? ((ior - 1.0f) / (ior + 1.0f)) * ((ior - 1.0f) / (ior + 1.0f)) : 0.04f;
  const Vec3 f0 = min(specular_colour * f0_ior, Vec3{1.0f}) * std::max(specular_factor, 0.0f);
  const std::string name = "material " + in_quotes(mat.name);
  if (transmitted > 0.0f) {
    if (transmitted < 1.0f) warnings_.add("partial transmission rendered as full transmission (glass)");
    if (roughness > 0.0f) warnings_.add("rough transmission rendered smooth");
    mat.illum = 7;
    mat.ni = ior > 0.0f ? ior : 1.5f;
    mat.tf = base;
    mat.kd = base;
  } else if (metallic >= 1.0f && roughness == 0.0f && pbr.metallicRoughnessTexture.index < 0 &&
             pbr.baseColorTexture.index < 0) {
    mat.illum = 3;  // a perfect mirror: the BRDF's limit, traced as the delta lobe it is
    mat.ks = base;
    mat.kd = Vec3{0.0f};
  } else {
    mat.metallic_roughness = true;
    mat.kd = base;
    mat.metallic = metallic;
    mat.roughness = roughness;
    mat.specular_f0 = f0;
    mat.specular_f90 = std::clamp(specular_factor, 0.0f, 1.0f);
    if (pbr.baseColorTexture.index >= 0) {
      mat.diffuse_texture = texture(pbr.baseColorTexture.index, pbr.baseColorTexture.texCoord,
                                    pbr.baseColorTexture.extensions, false, base, name + " baseColorTexture");
    }
    if (pbr.metallicRoughnessTexture.index >= 0) {
      const tg::TextureInfo& t = pbr.metallicRoughnessTexture;
      mat.metallic_roughness_texture =
          texture(t.index, t.texCoord, t.extensions, true, Vec3{1.0f}, name + " metallicRoughnessTexture");
    }
  }
  // The emissive texture times the factor (and strength); with a factor of 0 (the default) it
  // lights nothing and is not read.
  if (g.emissiveTexture.index >= 0 && mat.emissive()) {
    mat.emission_texture = texture(g.emissiveTexture.index, g.emissiveTexture.texCoord, g.emissiveTexture.extensions,
                                   false, Vec3{1.0f}, name + " emissiveTexture");
  }
  if (g.normalTexture.index >= 0) {
    mat.normal_texture = texture(g.normalTexture.index, g.normalTexture.texCoord, g.normalTexture.extensions, true,
                                 Vec3{1.0f}, name + " normalTexture");
    mat.normal_scale = float(g.normalTexture.scale);
    if (!std::isfinite(mat.normal_scale)) throw error("material " + in_quotes(mat.name) + ": normal scale not finite");
  }
  return mat;
}

TextureSlot Materials::texture(int index, int tex_coord, const tg::ExtensionMap& info_extensions, bool data, Vec3 tint,
                               const std::string& property) {
  const std::string what = property + ".index";
  if (index < 0 || size_t(index) >= model_.textures.size()) {
    throw error(what + ": texture " + std::to_string(index) + " does not exist (the file has " +
                std::to_string(model_.textures.size()) + ")");
  }
  const tg::Texture& t = model_.textures[size_t(index)];
  if (t.source < 0 || size_t(t.source) >= model_.images.size()) {
    throw error("texture " + std::to_string(index) + ": image " + std::to_string(t.source) + " does not exist");
  }
  TextureSlot slot;
  if (const tg::Value* transform = extension(info_extensions, "KHR_texture_transform")) {
    slot.transform = uv_transform(*transform, tex_coord, property);
  }
  if (tex_coord < 0) throw error(property + ".texCoord: " + std::to_string(tex_coord) + " is negative");
  if (tex_coord > 1) {
    warnings_.add("texture coordinate sets past TEXCOORD_1 not read: TEXCOORD_0 used instead");
    tex_coord = 0;
  }
  slot.uv_set = uint8_t(tex_coord);
  slot.sampler = sampler(t.sampler);
  const TextureUse use{t.source, data, data ? Vec3{1.0f} : tint};
  const auto [it, fresh] = texture_slots_.try_emplace(use, uint32_t(texture_uses_.size()));
  if (fresh) texture_uses_.push_back(use);
  slot.texture = it->second;
  return slot;
}

Sampler Materials::sampler(int index) {
  Sampler s;
  if (index < 0) return s;
  if (size_t(index) >= model_.samplers.size()) {
    throw error("sampler " + std::to_string(index) + " does not exist (the file has " +
                std::to_string(model_.samplers.size()) + ")");
  }
  const tg::Sampler& g = model_.samplers[size_t(index)];
  const auto wrap = [&](int mode, const char* axis) {
    switch (mode) {
      case TINYGLTF_TEXTURE_WRAP_REPEAT:
        return Wrap::Repeat;
      case TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE:
        return Wrap::ClampToEdge;
      case TINYGLTF_TEXTURE_WRAP_MIRRORED_REPEAT:
        return Wrap::MirroredRepeat;
      default:
        warnings_.add(std::string("sampler ") + axis + " of an unknown wrap mode: REPEAT used");
        return Wrap::Repeat;
    }
  };
  s.wrap_s = wrap(g.wrapS, "wrapS");
  s.wrap_t = wrap(g.wrapT, "wrapT");
  s.nearest = g.magFilter == TINYGLTF_TEXTURE_FILTER_NEAREST;
  // NEAREST and LINEAR minify from the full-resolution texels; the mip-map modes (and no filter
  // given) from the pyramid, always blended linearly between two levels.
  s.mipmaps = g.minFilter != TINYGLTF_TEXTURE_FILTER_NEAREST && g.minFilter != TINYGLTF_TEXTURE_FILTER_LINEAR;
  return s;
}

// KHR_texture_transform's uv' = T(offset) R(rotation) S(scale) uv in glTF's v-down space, made the
// same map of tracer's v-up coordinates (v = 1 - v_glTF on both sides); its texCoord replaces the
// textureInfo's.
UvTransform Materials::uv_transform(const tg::Value& t, int& tex_coord, const std::string& property) const {
  const std::string where = property + ".extensions.KHR_texture_transform";
  if (!t.IsObject()) throw error(where + ": not an object");
  const auto pair = [&](const char* key, double fallback, double out[2]) {
    out[0] = out[1] = fallback;
    if (!t.Has(key)) return;
    const tg::Value& v = t.Get(key);
    if (!v.IsArray() || v.ArrayLen() != 2 || !v.Get(0).IsNumber() || !v.Get(1).IsNumber()) {
      throw error(where + "." + key + ": not two numbers");
    }
    for (int k = 0; k < 2; ++k) out[k] = v.Get(k).GetNumberAsDouble();
  };
  double offset[2], scale[2];
  pair("offset", 0.0, offset);
  pair("scale", 1.0, scale);
  const double rotation = number(&t, "rotation", 0.0);
  for (double x : {offset[0], offset[1], scale[0], scale[1], rotation}) {
    if (!std::isfinite(x) || std::fabs(x) > 1e6) throw error(where + ": a value not finite or beyond +-1e6");
  }
  if (scale[0] == 0.0 || scale[1] == 0.0) throw error(where + ".scale: zero (every point would read one texel row)");
  if (t.Has("texCoord")) {
    const tg::Value& c = t.Get("texCoord");
    if (!c.IsInt()) throw error(where + ".texCoord: not an integer");
    tex_coord = c.GetNumberAsInt();
  }
  const double cs = std::cos(rotation), sn = std::sin(rotation);
  // glTF's map: u' = A u + B v + C, v' = D u + E v + F.
  const double A = cs * scale[0], B = sn * scale[1], C = offset[0];
  const double D = -sn * scale[0], E = cs * scale[1], F = offset[1];
  return {float(A), float(-B), float(B + C), float(-D), float(E), float(1.0 - E - F)};
}

void Materials::attach_textures(Scene& scene) {
  std::vector<int> images;
  for (const TextureUse& u : texture_uses_) images.push_back(u.image);
  std::sort(images.begin(), images.end());
  images.erase(std::unique(images.begin(), images.end()), images.end());
  const TextureBatch batch = read_and_decode(
      images.size(), [&](size_t k) { return read_image(images[k]); }, limits_, cancel_);
  // Slot -> scene texture (kInvalidIndex where its image failed). An image is stored once
  // untinted, however many slots read it so; each tinted copy counts against the texture budget
  // as a decoded image does (a file could otherwise ask for a thousand tints of one large image),
  // and past it the slot takes the untinted image, with a warning.
  uint64_t used = 0;
  for (const std::optional<Texture>& t : batch.decoded) {
    if (t) used += uint64_t(t->width()) * uint64_t(t->height()) * 4;
  }
  std::vector<uint32_t> plain(images.size(), kInvalidIndex);
  const auto untinted = [&](size_t k) {
    if (plain[k] == kInvalidIndex) {
      plain[k] = uint32_t(scene.textures.size());
      scene.textures.push_back(*batch.decoded[k]);
    }
    return plain[k];
  };
  std::vector<uint32_t> slot_texture(texture_uses_.size(), kInvalidIndex);
  for (size_t s = 0; s < texture_uses_.size(); ++s) {
    const TextureUse& u = texture_uses_[s];
    const size_t k = size_t(std::lower_bound(images.begin(), images.end(), u.image) - images.begin());
    if (!batch.decoded[k]) continue;
    const uint64_t bytes = uint64_t(batch.decoded[k]->width()) * uint64_t(batch.decoded[k]->height()) * 4;
    if (u.tint == Vec3{1.0f}) {
      slot_texture[s] = untinted(k);
    } else if (used + bytes > limits_.textures.max_total_bytes) {
      warnings_.add("image " + std::to_string(u.image) +
                    ": base colour factors past the texture budget: the untinted image is used");
      slot_texture[s] = untinted(k);
    } else {
      used += bytes;
      slot_texture[s] = uint32_t(scene.textures.size());
      scene.textures.push_back(batch.decoded[k]->tinted(u.tint));
    }
  }
  for (size_t k = 0; k < images.size(); ++k) {
    if (!batch.problem[k].empty())
      warnings_.add("image " + std::to_string(images[k]) + " not used: " + batch.problem[k]);
  }
  for (Material& m : scene.materials) {
    for (TextureSlot* t : m.slots())
      if (t->present()) t->texture = slot_texture[t->texture];
  }
}

EncodedTexture Materials::read_image(int index) const {
  const tg::Image& image = model_.images[size_t(index)];
  const std::string what = "image " + std::to_string(index);
  if (!image.image.empty()) {
    return encoded_texture(name_ + " " + what, std::string(image.image.begin(), image.image.end()), limits_.textures);
  }
  if (image.bufferView >= 0) throw InputError(name_ + " " + what + ": its buffer view could not be read");
  if (image.uri.empty()) throw InputError(name_ + " " + what + ": neither a URI nor a buffer view");
  if (base_dir_.empty()) throw InputError(name_ + " " + what + ": a scene read from memory refers to no files");
  const std::string uri = decode_uri(image.uri);
  std::string why;
  FileFinder finder;
  const std::optional<fs::path> file = finder.find(base_dir_, uri);
  if (!file) throw InputError((base_dir_ / uri).string() + ": not found");
  if (!inside_folder(fs::weakly_canonical(base_dir_), file->string(), &why))
    throw InputError(name_ + " " + what + ": " + why);
  return read_texture(*file, limits_.textures, cancel_);
}

}  // namespace tracer::gltf
