// Named views: a scene file with the camera and the light to render it with, one per line of a
// tab-separated file (../shared/scenes/views.tsv: inside Sponza's atrium, Sibenik's nave, the
// study's Cornell camera, ...). `tracer bench` measures on them and `tracer render --view` renders
// them.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "scene/scene.hpp"

namespace tracer {

struct View {
  std::string name;  // e.g. "sponza", "cornell-original"
  std::string obj;   // the scene file, resolved against the views file's directory
  CameraSpec camera;
  Vec3 light;  // one point light: the view replaces the scene's own lights with it
  std::string note;
};

// ../shared/scenes/views.tsv, looked for from the current directory and up to two levels below
// the project root (a build directory); that path even when it does not exist.
std::string default_views_path();

// The view a views.tsv beside the scene (in its directory or the one above) gives for the file
// at `obj_path`, if any. A views file that cannot be read or parsed counts as none, and the first
// such error goes to `problem` (for a warning).
std::optional<View> view_of_scene_file(const std::string& obj_path, std::string* problem = nullptr);

// Reads a views file: a header line (scene, obj, eye, look, up, fov, light, note), then one view
// per line, fields separated by tabs, vectors as x,y,z. Throws InputError naming file:line.
std::vector<View> load_views(const std::string& path);

// The view called `name`; throws UsageError naming `flag` and listing the names in `path` when
// there is none.
const View& find_view(const std::vector<View>& views, const std::string& name, const std::string& path,
                      const std::string& flag = "--view");

// Replaces the scene's lights with the view's point light (Scene::default_light_intensity()).
void apply_view_light(Scene& scene, const View& view);

}  // namespace tracer
