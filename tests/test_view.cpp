// `tracer view`'s server: the token on every request, bad changes refused with a message and no
// effect, frames over the event stream, and the image it shows equal, byte for byte, to
// `tracer render` with the command the page copies.
#include <gtest/gtest.h>
#include <httplib.h>

#include <nlohmann/json.hpp>

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <spawn.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <thread>

#include "frontend/render_options.hpp"
#include "frontend/settings_table.hpp"
#include "importers/scene_file.hpp"
#include "io/exr_io.hpp"
#include "io/image_io.hpp"
#include "scene/builtin.hpp"
#include "scene/camera.hpp"
#include "scene_writers.hpp"
#include "test_util.hpp"
#include "view/view_command.hpp"
#include "view/view_server.hpp"

namespace tracer {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

class ViewServerTest : public ::testing::Test {
 protected:
  // The scene the session shows (and the copied command names, through args_.scene).
  virtual Scene make_scene() { return make_cornell_box(); }
  void SetUp() override {
    std::signal(SIGPIPE, SIG_IGN);  // a request refused from its head may close before its body is sent
    dir_ = test::temp_dir();
    scene_ = make_scene();
    args_.settings.width = 64;
    args_.settings.height = 48;
    args_.spp = 4;
    args_.threads = 2;
    accel_ = build_accelerator(scene_, frontend::accel_options_for(args_));
    session_ = std::make_unique<view::ViewSession>(scene_, accel_, args_);
    server_ = std::make_unique<view::ViewServer>(*session_, "0123456789abcdef0123456789abcdef");
    port_ = server_->bind("127.0.0.1", 0);
    session_->start();
    listening_ = std::thread([this] { server_->listen(); });
  }
  void TearDown() override {
    session_->stop();
    server_->stop();
    listening_.join();
    fs::remove_all(dir_);
  }
  httplib::Client client() const { return httplib::Client("127.0.0.1", port_); }
  std::string with_token(const std::string& path) const {
    return path + (path.find('?') == std::string::npos ? "?" : "&") + "token=" + server_->token();
  }
  httplib::Result post(const std::string& body, const char* type = "application/json") {
    return client().Post(with_token("/control").c_str(), body, type);
  }
  // Waits for the frame that finishes the current state.
  std::shared_ptr<const view::Frame> complete_frame() {
    const uint64_t generation = session_->state()["generation"];
    uint64_t seen = 0;
    while (true) {
      auto f = session_->frames().wait_newer(seen, std::chrono::seconds(60));
      if (!f) return nullptr;
      seen = f->seq;
      if (f->complete && f->generation == generation) return f;
    }
  }
  // Runs the state's copied command (tracer render ...) writing `output`.
  test::CommandResult run_copied_command(const std::string& output) {
    std::string command = session_->state()["command"];
    EXPECT_EQ(command.rfind("tracer render ", 0), 0u) << command;
    return test::run_tracer(command.substr(std::string("tracer ").size()) + " -q -o " + output);
  }

  Scene scene_;
  frontend::RenderArgs args_;
  Accelerator accel_;
  std::unique_ptr<view::ViewSession> session_;
  std::unique_ptr<view::ViewServer> server_;
  std::thread listening_;
  int port_ = 0;
  std::string dir_;
};

TEST_F(ViewServerTest, EveryRequestNeedsTheToken) {
  for (const char* path : {"/", "/state", "/events", "/image.png", "/nonexistent"}) {
    auto r = client().Get(path);
    ASSERT_TRUE(r) << path;
    EXPECT_EQ(r->status, 403) << path;
    EXPECT_NE(r->body.find("token"), std::string::npos) << r->body;
    r = client().Get((std::string(path) + "?token=0123456789abcdef0123456789abcdee").c_str());
    EXPECT_EQ(r->status, 403) << path;
  }
  auto r = client().Post("/control", "{\"spp\": 2}", "application/json");
  EXPECT_EQ(r->status, 403);
  r = client().Get(with_token("/").c_str());
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 200);
  EXPECT_NE(r->body.find("<canvas"), std::string::npos);
  EXPECT_EQ(client().Get(with_token("/nonexistent").c_str())->status, 404);
}

TEST_F(ViewServerTest, BadChangesAreRefusedWithAMessageAndChangeNothing) {
  const json before = session_->state();
  const std::vector<std::pair<std::string, std::string>> cases = {
      // Every side out of the viewer's range names the viewer's range, also past the render's.
      {R"({"width": 0})", "width: must be between 1 and 4096, got 0"},
      {R"({"width": 20000})", "width: must be between 1 and 4096, got 20000"},
      {R"({"height": 5000})", "height: must be between 1 and 4096, got 5000"},
      {R"({"spp": 2.5})", "spp: expected a whole number"},
      {R"({"spp": "many"})", "spp: expected a number"},
      {R"({"max_depth": 65})", "max_depth: must be between 0 and 64, got 65"},
      {R"({"exposure": -1})", "exposure: must be above 0"},
      {R"({"fov": 180})", "fov: must be at least"},
      {R"({"aperture": -1})", "aperture: must be at least 0"},
      {R"({"focus_distance": 0})", "focus_distance: must be above 0"},
      {R"({"focus_at": [1]})", "focus_at: expected [x, y]"},
      {R"({"focus_at": [-5, 3]})", "focus_at: -5.000000,3.000000 lies outside the 64x48 image"},
      {R"({"integrator": "raster"})", "integrator: unknown integrator 'raster'"},
      {R"({"eye": [0, 1]})", "eye: expected [x, y, z]"},
      {R"({"eye": [0, 1, 1e300]})", "eye: 1e+300 is outside"},
      {R"({"look": [0, 1, "x"]})", "look: expected a number"},
      {R"({"up": [0, 0, 0]})", "up: must not be the zero vector"},
      {R"({"eye": [1, 1, 1], "look": [1, 1, 1]})", "the camera looks at its own position"},
      {R"({"spp": 8, "colour": 1})", "unknown field 'colour'"},
      {R"([1, 2])", "expected a JSON object"},
      {R"({"spp": )", "not JSON"},
  };
  for (const auto& [body, message] : cases) {
    const auto r = post(body);
    ASSERT_TRUE(r) << body;
    EXPECT_EQ(r->status, 400) << body;
    EXPECT_NE(r->body.find(message), std::string::npos) << body << " -> " << r->body;
  }
  const auto wrong_type = post(R"({"spp": 8})", "text/plain");
  EXPECT_EQ(wrong_type->status, 415);
  const auto oversized = post("{\"spp\": 8" + std::string(view::kMaxControlBytes, ' ') + "}");
  EXPECT_EQ(oversized->status, 413);
  EXPECT_EQ(session_->state(), before);  // the good field of a refused change is not applied either
}

TEST_F(ViewServerTest, ChangesRestartTheAccumulationExposureRetonesAoOnly) {
  const uint64_t generation = session_->state()["generation"];
  auto r = post(R"({"eye": [0.5, 1.25, 3], "spp": 2, "denoise": false})");
  ASSERT_EQ(r->status, 200) << r->body;
  json s = json::parse(r->body);
  EXPECT_EQ(s["generation"], generation + 1);
  EXPECT_EQ(s["eye"], json::array({0.5, 1.25, 3.0}));
  EXPECT_NE(std::string(s["command"]).find("--eye 0.5,1.25,3 "), std::string::npos) << s["command"];
  EXPECT_NE(std::string(s["command"]).find("--spp 2 "), std::string::npos) << s["command"];
  // Path tracing with adaptive sampling (the default without denoising) measures noise at the
  // exposure, so another
  // exposure restarts the film (as `tracer render` with it would stop other pixels); ao's film is
  // only tone-mapped again.
  r = post(R"({"exposure": 3})");
  s = json::parse(r->body);
  EXPECT_EQ(s["generation"], generation + 2);
  EXPECT_EQ(s["exposure"], 3.0);
  r = post(R"({"integrator": "ao"})");
  EXPECT_EQ(json::parse(r->body)["generation"], generation + 3);
  r = post(R"({"exposure": 2})");
  s = json::parse(r->body);
  EXPECT_EQ(s["generation"], generation + 3);
  EXPECT_EQ(s["exposure"], 2.0);
}

// Adaptive sampling's flags are path tracing's: launched with them, the view switches to ao without
// them (its copied command too) and back to path tracing with them.
TEST(ViewSession, AdaptiveFlagsFollowTheIntegrator) {
  const Scene scene = make_cornell_box();
  frontend::RenderArgs args;
  args.settings.width = 16;
  args.settings.height = 12;
  args.spp = 32;
  args.noise_threshold = 0.02;
  args.min_spp = 8;
  const Accelerator accel = build_accelerator(scene, frontend::accel_options_for(args));
  view::ViewSession session(scene, accel, args);
  const std::string launched = session.state()["command"];
  EXPECT_NE(launched.find("--noise-threshold 0.02 --min-spp 8"), std::string::npos) << launched;
  EXPECT_EQ(launched.find("--noise-threshold", launched.find("--noise-threshold") + 1), std::string::npos) << launched;
  const std::string ao = session.apply(json{{"integrator", "ao"}})["command"];
  EXPECT_NE(ao.find("--integrator ao"), std::string::npos) << ao;
  EXPECT_EQ(ao.find("--noise-threshold"), std::string::npos) << ao;
  EXPECT_EQ(ao.find("--min-spp"), std::string::npos) << ao;
  const std::string path = session.apply(json{{"integrator", "path"}})["command"];
  EXPECT_NE(path.find("--noise-threshold 0.02 --min-spp 8"), std::string::npos) << path;
}

// A click focuses the lens on the surface under it: the focus distance is that surface's distance
// along the view (brute force finds the same hit), and the copied command carries it.
TEST_F(ViewServerTest, AClickSetsTheFocusDistanceToTheSurfaceThere) {
  auto r = post(R"({"aperture": 0.02, "focus_at": [20.5, 30.5]})");
  ASSERT_EQ(r->status, 200) << r->body;
  const json s = json::parse(r->body);
  CameraSpec spec;
  spec.eye = Vec3{s["eye"][0], s["eye"][1], s["eye"][2]};
  spec.look = Vec3{s["look"][0], s["look"][1], s["look"][2]};
  spec.up = Vec3{s["up"][0], s["up"][1], s["up"][2]};
  spec.fov_degrees = s["fov"];
  const Camera camera(spec, 64, 48);
  const Ray ray = camera.ray_through(20.5f, 30.5f);
  const Accelerator brute = build_accelerator(scene_, AccelOptions{.kind = AccelKind::Brute});
  Hit hit;
  ASSERT_TRUE(brute.visit([&](const auto& accel) { return accel.intersect(ray, hit); }));
  const float want = hit.t * dot(ray.dir, camera.forward());
  EXPECT_NEAR(float(s["focus_distance"]), want, 1e-5f * want);
  EXPECT_EQ(s["aperture"], 0.02);
  const std::string command = s["command"];
  EXPECT_NE(command.find("--aperture 0.02 --focus-distance "), std::string::npos) << command;
  // Another surface, another distance; the lens stays.
  r = post(R"({"focus_at": [32, 2]})");
  ASSERT_EQ(r->status, 200) << r->body;
  const json other = json::parse(r->body);
  EXPECT_NE(other["focus_distance"], s["focus_distance"]);
  // Where the ray leaves the scene (the camera turned away from the box), the focus stays, said.
  r = post(R"({"eye": [1, 1, -3], "look": [1, 1, -10], "focus_at": [32, 24]})");
  ASSERT_EQ(r->status, 200) << r->body;
  const json away = json::parse(r->body);
  EXPECT_EQ(away["note"], "nothing there to focus on: the focus stays");
  EXPECT_NEAR(float(away["focus_distance"]), float(other["focus_distance"]), 1e-6f);
}

// The claim of the viewer: what it shows of a finished state is `tracer render`'s image, byte for
// byte, with the command it copies; for every integrator, and after a camera change.
TEST_F(ViewServerTest, FinishedImageIsTheCopiedCommandsRender) {
  const std::vector<std::string> changes = {
      R"({"eye": [0.3, 1.1, 2.6], "look": [0, 0.9, 0], "spp": 3})",
      R"({"integrator": "ao", "spp": 1, "width": 40})",
      R"({"integrator": "whitted", "spp": 2, "fov": 60, "exposure": 2.5})",
      R"({"integrator": "path", "spp": 2, "aperture": 0.05, "focus_at": [40, 20]})",
  };
  for (const std::string& change : changes) {
    ASSERT_EQ(post(change)->status, 200) << change;
    const auto frame = complete_frame();
    ASSERT_TRUE(frame) << change;
    EXPECT_EQ(frame->mime, "image/png");
    const auto png = client().Get(with_token("/image.png").c_str());
    ASSERT_EQ(png->status, 200);
    EXPECT_EQ(png->body, frame->bytes) << "the finished frame is the saved PNG";
    std::ofstream(dir_ + "/view.png", std::ios::binary) << png->body;
    const auto exr = client().Get(with_token("/image.exr").c_str());
    ASSERT_EQ(exr->status, 200);
    std::ofstream(dir_ + "/view.exr", std::ios::binary) << exr->body;

    const auto rendered = run_copied_command(dir_ + "/render.png");
    ASSERT_EQ(rendered.exit_code, 0) << rendered.output;
    const Image8 a = read_image(dir_ + "/view.png"), b = read_image(dir_ + "/render.png");
    EXPECT_EQ(a.width, b.width);
    EXPECT_EQ(a.rgb, b.rgb) << change;
    ASSERT_EQ(run_copied_command(dir_ + "/render.exr --exr float").exit_code, 0);
    const Framebuffer fa = read_exr(dir_ + "/view.exr"), fb = read_exr(dir_ + "/render.exr");
    for (int y = 0; y < fa.height(); ++y) {
      for (int x = 0; x < fa.width(); ++x) ASSERT_EQ(fa.radiance(x, y), fb.radiance(x, y)) << x << "," << y;
    }
  }
}

// An instanced scene (the Cornell box placed three times, kept once: a glTF written here) flies as
// a flat one does: its finished images, after camera moves, are the copied command's renders.
class InstancedViewTest : public ViewServerTest {
 protected:
  Scene make_scene() override {
    const Scene box = make_cornell_box();
    test::GltfWriteOptions options;
    for (const Affine& a : grid_placements(box.bounds, 3)) {
      for (uint32_t g = 0; g < box.geometries.size(); ++g) options.placements[g].push_back(a.column_major());
    }
    args_.scene.scene = dir_ + "/boxes.gltf";
    test::write_gltf(box, args_.scene.scene, options);
    return load_scene_file(args_.scene.scene);
  }
};

TEST_F(InstancedViewTest, FinishedImagesAreTheCopiedCommandsRenders) {
  ASSERT_TRUE(scene_.instanced());
  EXPECT_EQ(scene_.instances.size(), 3 * scene_.meshes.size());
  EXPECT_TRUE(accel_.instanced()) << accel_.name;
  for (const std::string& change : {std::string(R"({"eye": [-2, 3, 4], "look": [2, 1, -2], "spp": 2})"),
                                    std::string(R"({"integrator": "ao", "eye": [1, 1, 3], "spp": 1})")}) {
    ASSERT_EQ(post(change)->status, 200) << change;
    const auto frame = complete_frame();
    ASSERT_TRUE(frame) << change;
    std::ofstream(dir_ + "/view.png", std::ios::binary) << frame->bytes;
    const auto rendered = run_copied_command(dir_ + "/render.png");
    ASSERT_EQ(rendered.exit_code, 0) << rendered.output;
    EXPECT_EQ(read_image(dir_ + "/view.png").rgb, read_image(dir_ + "/render.png").rgb) << change;
  }
}

// Path tracing's image is denoised once the camera rests (the toggle on by default): the finished
// frame is `tracer render --denoise`'s image, and the toggle off restarts to the noisy one.
TEST_F(ViewServerTest, TheDenoiseToggleGivesTheCopiedCommandsImage) {
  EXPECT_EQ(session_->state()["denoise"], true);
  for (const bool denoise : {true, false}) {
    SCOPED_TRACE(denoise);
    const uint64_t before = session_->state()["generation"];
    ASSERT_EQ(post(json{{"integrator", "path"}, {"spp", 1}, {"denoise", denoise}}.dump())->status, 200);
    EXPECT_GT(session_->state()["generation"].get<uint64_t>(), before);
    const auto frame = complete_frame();
    ASSERT_TRUE(frame);
    EXPECT_EQ(frame->denoised, denoise);
    const std::string command = session_->state()["command"];
    EXPECT_EQ(command.find(" --denoise") != std::string::npos, denoise) << command;
    const auto png = client().Get(with_token("/image.png").c_str());
    ASSERT_EQ(png->status, 200);
    std::ofstream(dir_ + "/view.png", std::ios::binary) << png->body;
    const auto rendered = run_copied_command(dir_ + "/render.png");
    ASSERT_EQ(rendered.exit_code, 0) << rendered.output;
    EXPECT_EQ(read_image(dir_ + "/view.png").rgb, read_image(dir_ + "/render.png").rgb);
  }
  // Another integrator renders without it and keeps the toggle; a wrong type changes nothing.
  ASSERT_EQ(post(R"({"denoise": true, "integrator": "ao"})")->status, 200);
  EXPECT_EQ(session_->state()["denoise"], true);
  EXPECT_EQ(std::string(session_->state()["command"]).find("--denoise"), std::string::npos);
  const auto bad = post(R"({"denoise": 1})");
  EXPECT_EQ(bad->status, 400);
  EXPECT_NE(bad->body.find("denoise: expected true or false"), std::string::npos) << bad->body;
}

// A raised target goes on from the film (no preview, no pass again) and still ends on render's
// image; a lowered one starts again.
TEST_F(ViewServerTest, RaisingTheTargetGoesOnFromTheFilm) {
  ASSERT_EQ(post(R"({"spp": 4, "eye": [0.2, 1, 2.8]})")->status, 200);
  const auto at4 = complete_frame();
  ASSERT_TRUE(at4);
  ASSERT_EQ(post(R"({"spp": 16})")->status, 200);
  const uint64_t raised = session_->state()["generation"];
  std::vector<std::shared_ptr<const view::Frame>> frames;
  for (uint64_t seen = at4->seq;;) {
    auto f = session_->frames().wait_newer(seen, std::chrono::seconds(60));
    ASSERT_TRUE(f);
    seen = f->seq;
    if (f->generation == raised) frames.push_back(f);
    if (f->generation == raised && f->complete) break;
  }
  for (const auto& f : frames) {
    EXPECT_FALSE(f->preview);
    // Past the film's 4 samples, or on the way there within the pass that follows them.
    EXPECT_TRUE(f->spp > 4u || (f->spp == 4u && f->pass_fraction > 0.0)) << f->spp << " " << f->pass_fraction;
  }
  std::ofstream(dir_ + "/view.png", std::ios::binary) << frames.back()->bytes;
  ASSERT_EQ(run_copied_command(dir_ + "/render.png").exit_code, 0);
  EXPECT_EQ(read_image(dir_ + "/view.png").rgb, read_image(dir_ + "/render.png").rgb);

  ASSERT_EQ(post(R"({"spp": 8})")->status, 200);
  const auto lowered = complete_frame();
  ASSERT_TRUE(lowered);
  EXPECT_EQ(lowered->spp, 8u);
  std::ofstream(dir_ + "/view.png", std::ios::binary) << lowered->bytes;
  ASSERT_EQ(run_copied_command(dir_ + "/render.png").exit_code, 0);
  EXPECT_EQ(read_image(dir_ + "/view.png").rgb, read_image(dir_ + "/render.png").rgb);
}

TEST_F(ViewServerTest, EventStreamsGetTheNewestFrameEachSeveralAtOnce) {
  ASSERT_EQ(post(R"({"spp": 2})")->status, 200);
  ASSERT_TRUE(complete_frame());
  std::vector<std::thread> readers;
  std::vector<json> first(3);
  for (size_t i = 0; i < first.size(); ++i) {
    readers.emplace_back([&, i] {
      std::string buffer;
      client().Get(with_token("/events").c_str(), [&](const char* data, size_t n) {
        buffer.append(data, n);
        const size_t end = buffer.find("\n\n");
        if (end == std::string::npos) return true;
        const std::string event = buffer.substr(0, end);
        const std::string prefix = "event: frame\ndata: ";
        if (event.rfind(prefix, 0) == 0) first[i] = json::parse(event.substr(prefix.size()));
        return false;  // one frame is enough
      });
    });
  }
  for (std::thread& t : readers) t.join();
  const auto latest = session_->frames().latest();
  for (const json& f : first) {
    ASSERT_TRUE(f.is_object());
    EXPECT_EQ(f["seq"], latest->seq);  // a new stream starts at the newest frame
    EXPECT_EQ(f["complete"], true);
    EXPECT_EQ(f["spp"], 2);
    EXPECT_EQ(f["mime"], "image/png");
    EXPECT_FALSE(std::string(f["image"]).empty());
  }
}

// The copied command is the settings table's: every flag whose value differs from a default
// render's, in the table's order, each float as the shortest text that reads back the same.
TEST(ViewCommand, CopiedCommandSaysWhatDiffersFromADefaultRender) {
  frontend::RenderArgs a;
  a.scene.scene = "my scene.obj";
  a.scene.lights = {Vec3{0, 1, 0}, Vec3{2, 0.1f, 0}};
  a.accel = AccelKind::Bvh;
  a.eye = Vec3{1, 2, 3};
  a.look = Vec3{0, 0, 0};
  a.up = Vec3{0, 1, 0};
  a.fov = 45.3f;
  a.spp = 16;
  a.settings.width = 320;
  a.settings.height = 200;
  a.integrator = Integrator::Ao;
  a.packets = false;
  a.threads = 2;
  EXPECT_EQ(frontend::render_command(a),
            "tracer render --scene 'my scene.obj' --light 0,1,0 --light 2,0.1,0 --width 320 --height 200 "
            "--eye 1,2,3 --look 0,0,0 --up 0,1,0 --fov 45.3 --integrator ao --spp 16 --accel bvh --no-packets "
            "--threads 2");
  EXPECT_EQ(frontend::render_command(frontend::RenderArgs{}), "tracer render");
  EXPECT_EQ(frontend::shell_quote("it's"), "'it'\\''s'");
  EXPECT_EQ(frontend::shell_quote(""), "''");
}

// A raw connection to the viewer: what a browser, a script or an attacker sends, byte for byte.
class RawConnection {
 public:
  explicit RawConnection(int port) : fd_(::socket(AF_INET, SOCK_STREAM, 0)) {
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_port = htons(uint16_t(port));
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    ok_ = ::connect(fd_, reinterpret_cast<sockaddr*>(&a), sizeof a) == 0;
    timeval tv{5, 0};
    ::setsockopt(fd_, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
  }
  ~RawConnection() { ::close(fd_); }
  bool send(const std::string& s) { return ok_ && ::send(fd_, s.data(), s.size(), MSG_NOSIGNAL) == ssize_t(s.size()); }
  // Everything until the server closes (or 5 s pass).
  std::string response() {
    std::string out;
    char buf[4096];
    for (ssize_t n; (n = ::recv(fd_, buf, sizeof buf, 0)) > 0;) out.append(buf, size_t(n));
    return out;
  }

 private:
  int fd_;
  bool ok_ = false;
};

TEST_F(ViewServerTest, RequestHeadsAreCheckedBeforeTheirBodies) {
  const std::string host = "Host: 127.0.0.1:" + std::to_string(port_) + "\r\n";
  const std::string token = server_->token();
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"GET /state?token=" + token + "&token=bad HTTP/1.1\r\n" + host + "\r\n", "403 Forbidden"},
      {"GET /state?token=" + token + " HTTP/1.1\r\nHost: evil.example:" + std::to_string(port_) + "\r\n\r\n",
       "is not this viewer's address"},
      {"POST /control?token=" + token + " HTTP/1.1\r\n" + host +
           "Origin: http://evil.example\r\nContent-Type: application/json\r\nContent-Length: 2\r\n\r\n{}",
       "is not this viewer's page"},
      // A chunked body would bypass the 4 KiB limit (256 MB of it took 1.16 GB of memory).
      {"POST /control?token=" + token + " HTTP/1.1\r\n" + host +
           "Content-Type: application/json\r\nTransfer-Encoding: chunked\r\n\r\n2\r\n{}\r\n0\r\n\r\n",
       "Transfer-Encoding is not accepted"},
      // No Content-Length: answered at once, not after the read timeout.
      {"POST /control?token=" + token + " HTTP/1.1\r\n" + host + "Content-Type: application/json\r\n\r\n",
       "411 Length Required"},
  };
  for (const auto& [request, expected] : cases) {
    RawConnection c(port_);
    ASSERT_TRUE(c.send(request));
    const std::string response = c.response();
    EXPECT_NE(response.find(expected), std::string::npos) << request << "\n->\n" << response;
  }
  EXPECT_EQ(post(R"({"eye": [1e400, 0, 0]})")->status, 400);
  // The page itself is served by the address it was opened at.
  RawConnection ok(port_);
  ASSERT_TRUE(ok.send("GET /state?token=" + token + " HTTP/1.1\r\n" + host + "Connection: close\r\n\r\n"));
  EXPECT_EQ(ok.response().rfind("HTTP/1.1 200", 0), 0u);
}

// Fifty connections trickling header lines, with no token, do not starve the real client: each
// gets at most kHeadDeadline, and a client address at most a few connections still sending.
TEST_F(ViewServerTest, SlowConnectionsDoNotStarveTheRealClient) {
  std::atomic<bool> stop{false};
  std::vector<std::thread> slow;
  for (int i = 0; i < 50; ++i) {
    slow.emplace_back([&, i] {
      // Each connection trickles a header line a second for as long as the server takes them
      // (cpp-httplib's per-read timeout, 5 s, never trips), then the next one comes.
      while (!stop) {
        RawConnection c(port_);
        if (c.send("GET /state HTTP/1.1\r\n")) {
          while (!stop && c.send("X-Slow-" + std::to_string(i) + ": 1\r\n")) {
            for (int k = 0; k < 10 && !stop; ++k) std::this_thread::sleep_for(std::chrono::milliseconds(100));
          }
        }
        std::this_thread::sleep_for(std::chrono::milliseconds(100));
      }
    });
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(1500));  // every slow connection is in
  int answered = 0;
  for (int i = 0; i < 10; ++i) {
    httplib::Client c = client();
    // The attack only ever holds a request up to 2 s, and a starved client is never answered: 20 s
    // leaves room for a machine loaded by other tests (5 s failed once under ctest -j2).
    c.set_read_timeout(20, 0);
    c.set_connection_timeout(20, 0);
    const auto r = c.Get(with_token("/state").c_str());
    answered += r && r->status == 200 ? 1 : 0;
  }
  stop = true;
  for (std::thread& t : slow) t.join();
  EXPECT_EQ(answered, 10);
}

// A second viewer on the same port is refused instead of sharing the connections (SO_REUSEPORT).
TEST_F(ViewServerTest, ASecondServerOnThePortIsRefused) {
  view::ViewServer second(*session_, "fedcba9876543210fedcba9876543210");
  EXPECT_THROW(second.bind("127.0.0.1", port_), UsageError);
}

// A stop that comes before the listening thread has begun, or while it begins, is not lost:
// cpp-httplib's own stop() does nothing until its accept loop runs. Repeated, since the window
// is a few microseconds; a lost stop hangs here (ctest's timeout names the test).
TEST_F(ViewServerTest, AStopBeforeOrDuringListenIsNotLost) {
  for (int i = 0; i < 200; ++i) {
    view::ViewServer early(*session_, "fedcba9876543210fedcba9876543210");
    early.bind("127.0.0.1", 0);
    if (i % 2 == 0) early.stop();  // before listen() is called at all
    std::thread listening([&] { early.listen(); });
    if (i % 2 == 1) early.stop();  // while it starts
    listening.join();
  }
}

TEST(ViewCommand, BadFlagsAreRefused) {
  for (const auto& [args, message] : std::vector<std::pair<std::string, std::string>>{
           {"view --port 70000", "--port"},
           {"view --frames 3", "--frames: not for tracer view"},
           {"view --width 5000", "--width"},
           {"view --listen 256.1.1.1 --port 0", "cannot listen on 256.1.1.1"},
           {"view --listen '' --port 0", "--listen: an empty address"},
       }) {
    const test::CommandResult r = test::run_tracer(args);
    EXPECT_EQ(r.exit_code, 2) << args << ": " << r.output;
    EXPECT_NE(r.output.find(message), std::string::npos) << args << ": " << r.output;
  }
}

// Ctrl-C while the viewer starts (H1 of the sixth hostile round), sent to the real process 20
// times at each delay after it is spawned; it must end within 3 s with the shell's 130 (its
// own exit, or SIGINT's default action before it can catch the signal).
// - Started as a terminal or a supervisor starts it (SIGINT at its default): at 0, 1, 5, 10 ms.
// - Started as a script's background job (`tracer view &`: SIGINT ignored until tracer installs
//   its handlers): at 0, 1, 5 and 10 ms after /proc shows the handler installed, which is now
//   before the libraries' constructors run; the stop raised there must be looked at when the
//   viewer starts. Before the handler, the kernel discards the signal before any of tracer's code
//   runs (the dynamic loader's 11 ms or more; docs/RELIABILITY.md), so the delays count from it,
//   not from the spawn: a load that slows the start moves nothing.
// Whether process `pid` catches SIGINT (its SigCgt mask in /proc) within `seconds`.
bool catches_sigint_within(pid_t pid, double seconds) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  const std::string path = "/proc/" + std::to_string(pid) + "/status";
  while (std::chrono::steady_clock::now() < end) {
    std::ifstream in(path);
    for (std::string line; std::getline(in, line);) {
      if (line.rfind("SigCgt:", 0) == 0 && (std::stoull(line.substr(7), nullptr, 16) >> (SIGINT - 1)) & 1) return true;
    }
    std::this_thread::sleep_for(std::chrono::microseconds(200));
  }
  return false;
}

TEST(ViewCommand, ACtrlCWhileItStartsStopsIt) {
  if (test::kUnderSanitizer) GTEST_SKIP() << "a sanitizer's start-up moves the windows";
  const std::string exe = TRACER_EXE;
  std::vector<std::string> words = {exe, "view", "--port", "0", "-q"};
  std::vector<char*> argv;
  for (std::string& w : words) argv.push_back(w.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t files;
  posix_spawn_file_actions_init(&files);
  posix_spawn_file_actions_addopen(&files, STDOUT_FILENO, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_addopen(&files, STDERR_FILENO, "/dev/null", O_WRONLY, 0);
  const auto tries = [&](bool ignored, int delay_ms) {
    // Every signal at its default in the child but, for a background job, SIGINT: ignored in
    // this process while it spawns, as the shell's child ignores it before its exec.
    posix_spawnattr_t attr;
    posix_spawnattr_init(&attr);
    sigset_t defaults;
    sigfillset(&defaults);
    if (ignored) sigdelset(&defaults, SIGINT);
    posix_spawnattr_setsigdefault(&attr, &defaults);
    posix_spawnattr_setflags(&attr, POSIX_SPAWN_SETSIGDEF);
    struct sigaction ignore {
    }, previous{};
    ignore.sa_handler = SIG_IGN;
    int failed = 0;
    for (int i = 0; i < 20; ++i) {
      pid_t pid = -1;
      if (ignored) ::sigaction(SIGINT, &ignore, &previous);
      const int spawned = posix_spawn(&pid, exe.c_str(), &files, &attr, argv.data(), environ);
      if (ignored) ::sigaction(SIGINT, &previous, nullptr);
      if (spawned != 0) return -1;
      if (ignored && !catches_sigint_within(pid, 10.0)) {
        ++failed;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(delay_ms));
      ::kill(pid, SIGINT);
      int status = 0;
      bool ended = false;
      for (int k = 0; k < 300 && !ended; ++k) {  // 3 s
        ended = ::waitpid(pid, &status, WNOHANG) == pid;
        if (!ended) std::this_thread::sleep_for(std::chrono::milliseconds(10));
      }
      if (!ended) {
        ::kill(pid, SIGKILL);
        ::waitpid(pid, &status, 0);
      }
      const bool shell_130 = (WIFEXITED(status) && WEXITSTATUS(status) == 130) ||
                             (!ignored && WIFSIGNALED(status) && WTERMSIG(status) == SIGINT);
      failed += ended && shell_130 ? 0 : 1;
    }
    posix_spawnattr_destroy(&attr);
    return failed;
  };
  for (const int delay_ms : {0, 1, 5, 10}) EXPECT_EQ(tries(false, delay_ms), 0) << "SIGINT at " << delay_ms << " ms";
  for (const int delay_ms : {0, 1, 5, 10}) {
    EXPECT_EQ(tries(true, delay_ms), 0) << "SIGINT " << delay_ms << " ms after a background job caught it";
  }
  posix_spawn_file_actions_destroy(&files);
}
}  // namespace
}  // namespace tracer
