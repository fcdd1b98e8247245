// Texture addressing as glTF defines it, written once for every slot: the samplers' wrap modes
// and filters at exact texels, KHR_texture_transform against the specification's formula, the
// second set of coordinates, and each bad property's one-line error.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "importers/gltf_loader.hpp"
#include "io/image_io.hpp"
#include "scene/emission.hpp"
#include "shade/material_bsdf.hpp"
#include "shade/texture_lookup.hpp"
#include "test_util.hpp"

namespace tracer {
namespace {

// A 4 x 1 texture of four greys, texel x holding code 50 + 60 x (linear values all distinct).
Texture ramp() {
  std::vector<uint8_t> rgb;
  for (int x = 0; x < 4; ++x) rgb.insert(rgb.end(), 3, uint8_t(50 + 60 * x));
  return Texture(4, 1, rgb);
}

float texel_x(const Texture& t, int x) { return t.texel(x, 0).x; }

TEST(TextureSlots, WrapModesReadTheTexelsTheSpecificationSays) {
  const Texture t = ramp();
  Sampler s;
  s.nearest = true;
  // u in texels: 5.5 / 4 lies in texel 1 of the second period, -0.5 / 4 just left of the image.
  const float right = 5.5f / 4.0f, left = -0.5f / 4.0f, far = 13.5f / 4.0f;
  s.wrap_s = Wrap::Repeat;
  EXPECT_EQ(t.bilinear(right, 0.5f, s).x, texel_x(t, 1));
  EXPECT_EQ(t.bilinear(left, 0.5f, s).x, texel_x(t, 3));
  s.wrap_s = Wrap::ClampToEdge;
  EXPECT_EQ(t.bilinear(right, 0.5f, s).x, texel_x(t, 3));
  EXPECT_EQ(t.bilinear(left, 0.5f, s).x, texel_x(t, 0));
  EXPECT_EQ(t.bilinear(-1e30f, 0.5f, s).x, texel_x(t, 0));
  EXPECT_EQ(t.bilinear(1e30f, 0.5f, s).x, texel_x(t, 3));
  s.wrap_s = Wrap::MirroredRepeat;
  EXPECT_EQ(t.bilinear(right, 0.5f, s).x, texel_x(t, 2));  // texel 5 of 8: the mirror's second
  EXPECT_EQ(t.bilinear(left, 0.5f, s).x, texel_x(t, 0));
  EXPECT_EQ(t.bilinear(far, 0.5f, s).x, texel_x(t, 2));  // 13 mod 8 = 5
  // Linear filtering at an edge under clamp: the edge texel alone; under repeat, half the far one.
  s.nearest = false;
  s.wrap_s = Wrap::ClampToEdge;
  EXPECT_FLOAT_EQ(t.bilinear(0.0f, 0.5f, s).x, texel_x(t, 0));
  s.wrap_s = Wrap::Repeat;
  EXPECT_FLOAT_EQ(t.bilinear(0.0f, 0.5f, s).x, 0.5f * (texel_x(t, 0) + texel_x(t, 3)));
  // A non-finite coordinate reads as 0, not out of bounds.
  EXPECT_TRUE(std::isfinite(t.bilinear(std::nanf(""), 0.5f, s).x));
}

TEST(TextureSlots, NearestMagnifiesAndNoMipmapsMinifiesFromTheTexels) {
  const Texture t = ramp();
  Sampler s;
  const float u = 1.25f / 4.0f;  // a quarter past texel 1's left edge
  EXPECT_FLOAT_EQ(t.bilinear(u, 0.5f, s).x, 0.25f * texel_x(t, 0) + 0.75f * texel_x(t, 1));
  s.nearest = true;
  EXPECT_EQ(t.bilinear(u, 0.5f, s).x, texel_x(t, 1));
  // Far minified: the pyramid's top is the mean; without mip-maps the texels themselves.
  s.nearest = false;
  EXPECT_NE(t.filtered(u, 0.5f, 10.0f, s).x, t.bilinear(u, 0.5f, s).x);
  s.mipmaps = false;
  EXPECT_EQ(t.filtered(u, 0.5f, 10.0f, s).x, t.bilinear(u, 0.5f, s).x);
}

// A slot reads its own set of coordinates, moved by its transform.
TEST(TextureSlots, ASlotReadsItsSetThroughItsTransform) {
  Scene s = test::scene_of({Triangle{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}});
  s.corner_uvs = {{0.1f, 0.5f}, {0.1f, 0.5f}, {0.1f, 0.5f}};   // texel 0 everywhere
  s.corner_uvs1 = {{0.6f, 0.5f}, {0.6f, 0.5f}, {0.6f, 0.5f}};  // texel 2 everywhere
  s.textures.push_back(ramp());
  TextureSlot slot;
  slot.texture = 0;
  slot.sampler.nearest = true;
  Hit hit;
  hit.tri = 0;
  hit.u = hit.v = 0.25f;
  EXPECT_EQ(slot_color(s, hit, slot, Vec3{-1.0f}).x, texel_x(s.textures[0], 0));
  slot.uv_set = 1;
  EXPECT_EQ(slot_color(s, hit, slot, Vec3{-1.0f}).x, texel_x(s.textures[0], 2));
  slot.transform.c = 0.25f;  // one texel to the right
  EXPECT_EQ(slot_color(s, hit, slot, Vec3{-1.0f}).x, texel_x(s.textures[0], 3));
  s.corner_uvs1.clear();  // no such set: the fallback
  EXPECT_EQ(slot_color(s, hit, slot, Vec3{-1.0f}).x, -1.0f);
}

// One triangle with two sets of coordinates and a base colour texture whose textureInfo carries
// `info` (JSON members after "index": 0) and whose texture names `sampler`; its image `image`.
std::string textured_gltf(const std::string& info, const std::string& sampler = "", bool second_set = true,
                          const Image8& image = Image8{4, 1, std::vector<uint8_t>(12, 200)}) {
  const std::string png = encode_png(image);
  const std::string data =
      test::bytes_of<float>({0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 1, 0.5f, 0.5f, 1, 0.5f, 0.5f, 1});
  return R"({"asset": {"version": "2.0"}, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
    "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "TEXCOORD_0": 1)" +
         std::string(second_set ? R"(, "TEXCOORD_1": 2)" : "") + R"(}, "material": 0}]}],
    "materials": [{"name": "m", "pbrMetallicRoughness": {"metallicFactor": 0, "baseColorTexture": {"index": 0)" +
         info + R"(}}}],
    "textures": [{"source": 0)" +
         (sampler.empty() ? "" : R"(, "sampler": 0)") + R"(}], )" +
         (sampler.empty() ? "" : R"("samplers": [)" + sampler + "], ") +
         R"("images": [{"uri": "data:image/png;base64,)" + test::base64(png) + R"("}],
    "buffers": [{"uri": "data:application/octet-stream;base64,)" +
         test::base64(data) + R"(", "byteLength": 84}],
    "bufferViews": [{"buffer": 0, "byteLength": 36}, {"buffer": 0, "byteOffset": 36, "byteLength": 24},
                    {"buffer": 0, "byteOffset": 60, "byteLength": 24}],
    "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]},
                  {"bufferView": 1, "componentType": 5126, "count": 3, "type": "VEC2"},
                  {"bufferView": 2, "componentType": 5126, "count": 3, "type": "VEC2"}]})";
}

TEST(TextureSlots, GltfTransformSetAndSamplerReachTheSlot) {
  std::vector<std::string> warnings;
  // A file that requires the extension (as Blender's exporter writes a Mapping node) loads.
  std::string json = textured_gltf(R"(, "texCoord": 0, "extensions": {"KHR_texture_transform":
      {"offset": [0.25, -0.5], "rotation": 0.7, "scale": [2, 3], "texCoord": 1}})",
                                   R"({"wrapS": 33071, "wrapT": 33648, "magFilter": 9728, "minFilter": 9729})");
  json.insert(1, R"("extensionsUsed": ["KHR_texture_transform"], "extensionsRequired": ["KHR_texture_transform"], )");
  const Scene s = load_gltf_from_memory(json, "t.gltf", [&](const std::string& w) { warnings.push_back(w); });
  EXPECT_TRUE(warnings.empty()) << warnings.front();
  ASSERT_EQ(s.corner_uvs1.size(), 3u);
  EXPECT_EQ(s.corner_uvs1[0].x, 0.5f);
  EXPECT_EQ(s.corner_uvs1[0].y, 0.5f);  // glTF's v 0.5 flipped
  const TextureSlot& slot = s.materials[0].diffuse_texture;
  ASSERT_TRUE(slot.present());
  EXPECT_EQ(slot.uv_set, 1);  // the transform's texCoord wins
  EXPECT_EQ(slot.sampler.wrap_s, Wrap::ClampToEdge);
  EXPECT_EQ(slot.sampler.wrap_t, Wrap::MirroredRepeat);
  EXPECT_TRUE(slot.sampler.nearest);
  EXPECT_FALSE(slot.sampler.mipmaps);
  // The specification's matrix T * R * S on glTF coordinates (u, v down), against the slot's map
  // of tracer's (u, 1 - v).
  const double c = std::cos(0.7), n = std::sin(0.7);
  for (const auto& [u, v] : {std::pair{0.0, 0.0}, std::pair{0.3, 0.8}, std::pair{-1.5, 2.25}}) {
    const double gu = c * 2 * u + n * 3 * v + 0.25, gv = -n * 2 * u + c * 3 * v - 0.5;
    const Vec2 t = slot.transform.apply({float(u), float(1.0 - v)});
    EXPECT_NEAR(t.x, gu, 1e-5) << u << "," << v;
    EXPECT_NEAR(t.y, 1.0 - gv, 1e-5) << u << "," << v;
  }
}

TEST(TextureSlots, BadAddressingIsOneLineNamingTheProperty) {
  const std::string transform = R"(, "extensions": {"KHR_texture_transform": )";
  const std::pair<std::string, std::string> cases[] = {
      {textured_gltf(transform + R"({"scale": [0, 1]}})"),
       "t.gltf: material 'm' baseColorTexture.extensions.KHR_texture_transform.scale: zero"},
      {textured_gltf(transform + R"({"offset": [1e30, 0]}})"),
       "t.gltf: material 'm' baseColorTexture.extensions.KHR_texture_transform: a value not finite or beyond"},
      {textured_gltf(transform + R"({"offset": [1]}})"),
       "t.gltf: material 'm' baseColorTexture.extensions.KHR_texture_transform.offset: not two numbers"},
      {textured_gltf(transform + R"({"texCoord": 0.5}})"),
       "t.gltf: material 'm' baseColorTexture.extensions.KHR_texture_transform.texCoord: not an integer"},
      {textured_gltf(R"(, "texCoord": 1)", "", false),
       "t.gltf: mesh 0 primitive 0: material 'm' reads TEXCOORD_1, which the primitive lacks"},
      {textured_gltf("", R"({"wrapS": 33071})")
           .replace(textured_gltf("", R"({"wrapS": 33071})").find(R"("sampler": 0)"), 12, R"("sampler": 4)"),
       "t.gltf: sampler 4 does not exist (the file has 1)"},
  };
  for (const auto& [json, want] : cases) {
    const std::string got = test::gltf_load_error(json);
    EXPECT_NE(got.find(want), std::string::npos) << got;
    EXPECT_EQ(got.find('\n'), std::string::npos) << got;
  }
}

// The specification allows unknown enum values to be ignored: a grouped warning and REPEAT.
TEST(TextureSlots, AnUnknownWrapModeIsAWarningAndRepeats) {
  std::vector<std::string> warnings;
  const Scene s = load_gltf_from_memory(textured_gltf("", R"({"wrapS": 1234})"), "t.gltf",
                                        [&](const std::string& w) { warnings.push_back(w); });
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("sampler wrapS of an unknown wrap mode: REPEAT used"), std::string::npos) << warnings[0];
  EXPECT_EQ(s.materials[0].diffuse_texture.sampler.wrap_s, Wrap::Repeat);
}

TEST(TextureSlots, MetallicRoughnessTextureScalesTheFactorsAsData) {
  // Blue times metallicFactor, green times roughnessFactor, the bytes as data (no sRGB decoding:
  // 128 is 0.502, not sRGB's 0.216).
  std::vector<uint8_t> texels(12);
  for (size_t i = 0; i < texels.size(); ++i) texels[i] = i % 3 == 0 ? 10 : i % 3 == 1 ? 128 : 64;
  std::string json = textured_gltf("", "", true, Image8{4, 1, texels});
  const std::string base = R"({"metallicFactor": 0, "baseColorTexture": {"index": 0)";
  json.replace(json.find(base), base.size(),
               R"({"metallicFactor": 0.5, "roughnessFactor": 0.8, "metallicRoughnessTexture": {"index": 0)");
  const Scene s = load_gltf_from_memory(json, "t.gltf");
  const Material& m = s.materials[0];
  ASSERT_EQ(m.surface(), SurfaceKind::MetallicRoughness);
  ASSERT_TRUE(m.metallic_roughness_texture.present());
  EXPECT_FALSE(m.diffuse_texture.present());
  Hit hit;
  hit.tri = 0;
  hit.u = hit.v = 0.3f;
  const MaterialPoint p = material_point(s, hit, m);
  EXPECT_NEAR(p.metallic, 0.5f * 64.0f / 255.0f, 1e-5f);
  EXPECT_NEAR(p.roughness, 0.8f * 128.0f / 255.0f, 1e-5f);
  EXPECT_EQ(p.color, Vec3{1.0f});  // no base colour texture: the factor's default
}

TEST(TextureSlots, EmissiveTextureTimesTheFactorIsWhatASurfaceEmits) {
  std::vector<uint8_t> texels(12, 0);
  texels[9] = texels[10] = texels[11] = 255;  // the last texel white, the rest black
  std::string json = textured_gltf("", "", true, Image8{4, 1, texels});
  const std::string base = R"("pbrMetallicRoughness": {"metallicFactor": 0, "baseColorTexture": {"index": 0}})";
  const std::string emissive = R"("emissiveFactor": [1, 0.5, 0.25], "emissiveTexture": {"index": 0},
      "pbrMetallicRoughness": {"metallicFactor": 0})";
  json.replace(json.find(base), base.size(), emissive);
  const Scene s = load_gltf_from_memory(json, "t.gltf");
  ASSERT_TRUE(s.materials[0].emission_texture.present());
  // Along the edge from corner 0 (u 0) to corner 1 (u 1): the white texel's centre is at u
  // 0.875, the first black one's at 0.125.
  EXPECT_EQ(emitted_radiance(s, 0, 0.125f, 0.0f), Vec3{0.0f});
  const Vec3 lit = emitted_radiance(s, 0, 0.875f, 0.0f);
  EXPECT_NEAR(lit.x, 1.0f, 1e-5f);
  EXPECT_NEAR(lit.y, 0.5f, 1e-5f);
  EXPECT_NEAR(lit.z, 0.25f, 1e-5f);
  // A factor of 0 (glTF's default) emits nothing, whatever the texture: it is not read.
  const std::string factor = R"("emissiveFactor": [1, 0.5, 0.25])";
  json.replace(json.find(factor), factor.size(), R"("emissiveFactor": [0, 0, 0])");
  const Scene dark = load_gltf_from_memory(json, "t.gltf");
  EXPECT_FALSE(dark.materials[0].emission_texture.present());
  EXPECT_TRUE(dark.emitters.empty());
}

}  // namespace
}  // namespace tracer
