// glTF's metallic-roughness materials as tracer's (the table in docs/FORMATS.md), and the images
// they use, read and decoded in parallel within the scene's texture budget.
#pragma once

#include <cstdint>
#include <filesystem>
#include <map>
#include <string>
#include <tuple>
#include <vector>

#include "importers/gltf_document.hpp"
#include "scene/scene.hpp"

namespace tracer::gltf {

class Materials {
 public:
  Materials(const tinygltf::Model& model, std::string name, std::filesystem::path base_dir, const LoadLimits& limits,
            CancelFlag cancel, WarningLog& warnings)
      : model_(model),
        name_(std::move(name)),
        base_dir_(std::move(base_dir)),
        limits_(limits),
        cancel_(cancel),
        warnings_(warnings) {}

  // The index in scene.materials of glTF material `index` (-1: tracer's grey default), appended
  // at first use. Its textures are slots until attach_textures().
  uint32_t material(int index, Scene& scene);
  // Reads and decodes each image the materials use (in parallel, within the texture budget, in
  // image order), appends them to scene.textures and points the materials at them; an image that
  // cannot be read leaves its materials their factors, with a warning.
  void attach_textures(Scene& scene);

 private:
  // A texture a material asked for: an image, how it is read (colour, or data for a normal map),
  // and the linear factor folded into its texels.
  struct TextureUse {
    int image = -1;
    bool data = false;
    Vec3 tint{1.0f};
    auto operator<=>(const TextureUse& o) const {
      return std::tie(image, data, tint.x, tint.y, tint.z) <=> std::tie(o.image, o.data, o.tint.x, o.tint.y, o.tint.z);
    }
    bool operator==(const TextureUse&) const = default;
  };

  InputError error(const std::string& what) const { return InputError(name_ + ": " + what); }
  Material map_material(const tinygltf::Material& g, int index);
  // The slot of texture `index` read through set `tex_coord` as colour (tinted) or as data, with
  // its sampler and the textureInfo's KHR_texture_transform; its texture is a use of texture_uses_
  // until attach_textures() makes it the scene's.
  TextureSlot texture(int index, int tex_coord, const tinygltf::ExtensionMap& info_extensions, bool data, Vec3 tint,
                      const std::string& property);
  Sampler sampler(int index);
  UvTransform uv_transform(const tinygltf::Value& t, int& tex_coord, const std::string& property) const;
  // An image's encoded bytes: from a buffer view, a data: URI (tinygltf decoded it) or a file
  // inside the scene's folder.
  EncodedTexture read_image(int index) const;

  const tinygltf::Model& model_;
  std::string name_;
  std::filesystem::path base_dir_;
  const LoadLimits& limits_;
  CancelFlag cancel_;
  WarningLog& warnings_;
  std::map<int, uint32_t> materials_;
  std::map<TextureUse, uint32_t> texture_slots_;
  std::vector<TextureUse> texture_uses_;
};

}  // namespace tracer::gltf
