// `tracer view`'s server: the token on every request, bad changes refused with a message and no
// effect, frames over the event stream, and the image it shows equal, byte for byte, to
// `tracer render` with the command the page copies.
#include <gtest/gtest.h>
#include <httplib.h>

#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <thread>

#include "io/exr_io.hpp"
#include "io/image_io.hpp"
#include "scene/builtin.hpp"
#include "test_util.hpp"
#include "view/view_command.hpp"
#include "view/view_server.hpp"

namespace tracer {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

class ViewServerTest : public ::testing::Test {
 protected:
  void SetUp() override {
    scene_ = make_cornell_box();
    args_.settings.width = 64;
    args_.settings.height = 48;
    args_.spp = 4;
    args_.threads = 2;
    accel_ = build_accelerator(scene_, driver::accel_options_for(args_));
    session_ = std::make_unique<view::ViewSession>(scene_, accel_, args_, std::vector<std::string>{"--threads", "2"},
                                                   view::kViewerFlags);
    server_ = std::make_unique<view::ViewServer>(*session_, "0123456789abcdef0123456789abcdef");
    port_ = server_->bind("127.0.0.1", 0);
    session_->start();
    listening_ = std::thread([this] { server_->listen(); });
    dir_ = test::temp_dir();
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
  driver::RenderArgs args_;
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
      {R"({"width": 0})", "width: 0 is outside [1, 4096]"},
      {R"({"height": 5000})", "height: 5000 is outside [1, 4096]"},
      {R"({"spp": 2.5})", "spp: expected a whole number"},
      {R"({"spp": "many"})", "spp: expected a number"},
      {R"({"max_depth": 65})", "max_depth: 65 is outside [0, 64]"},
      {R"({"exposure": -1})", "exposure: -1 is outside"},
      {R"({"fov": 180})", "fov: 180 is outside"},
      {R"({"integrator": "raster"})", "integrator: unknown integrator 'raster'"},
      {R"({"eye": [0, 1]})", "eye: expected [x, y, z]"},
      {R"({"eye": [0, 1, 1e300]})", "eye: 1e+300 is outside"},
      {R"({"look": [0, 1, "x"]})", "look: expected a number"},
      {R"({"up": [0, 0, 0]})", "--up: must not be the zero vector"},
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

TEST_F(ViewServerTest, ChangesRestartTheAccumulationExposureOnlyRetones) {
  const uint64_t generation = session_->state()["generation"];
  auto r = post(R"({"eye": [0.5, 1.25, 3], "spp": 2})");
  ASSERT_EQ(r->status, 200) << r->body;
  json s = json::parse(r->body);
  EXPECT_EQ(s["generation"], generation + 1);
  EXPECT_EQ(s["eye"], json::array({0.5, 1.25, 3.0}));
  EXPECT_NE(std::string(s["command"]).find("--eye 0.5,1.25,3 "), std::string::npos) << s["command"];
  EXPECT_NE(std::string(s["command"]).find("--spp 2 "), std::string::npos) << s["command"];
  r = post(R"({"exposure": 3})");
  s = json::parse(r->body);
  EXPECT_EQ(s["generation"], generation + 1);
  EXPECT_EQ(s["exposure"], 3.0);
}

// The claim of the viewer: what it shows of a finished state is `tracer render`'s image, byte for
// byte, with the command it copies; for every integrator, and after a camera change.
TEST_F(ViewServerTest, FinishedImageIsTheCopiedCommandsRender) {
  const std::vector<std::string> changes = {
      R"({"eye": [0.3, 1.1, 2.6], "look": [0, 0.9, 0], "spp": 3})",
      R"({"integrator": "ao", "spp": 1, "width": 40})",
      R"({"integrator": "whitted", "spp": 2, "fov": 60, "exposure": 2.5})",
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

TEST(ViewCommand, CopiedCommandKeepsTheUsersFlagsAndStatesTheView) {
  driver::RenderArgs a;
  a.eye = "1,2,3";
  a.look = "0,0,0";
  a.up = "0,1,0";
  a.fov = 45.0;
  a.spp = 16;
  a.settings.width = 320;
  a.settings.height = 200;
  const std::vector<std::string> typed = {
      "my scene.obj", "--eye",        "9,9,9", "--width=64", "-v1,1,1", "--port", "0",     "--accel",
      "bvh",          "--listen=::1", "-l",    "2,2,2",      "--light", "0,1,0",  "--spp", "4"};
  const std::string command = view::render_command(a, typed, view::kViewerFlags);
  EXPECT_EQ(command,
            "tracer render 'my scene.obj' --accel bvh --light 0,1,0 --eye 1,2,3 --look 0,0,0 --up 0,1,0 --fov 45 "
            "--width 320 --height 200 --integrator path --spp 16 --max-depth 8 --exposure 1.5");
  EXPECT_EQ(view::shell_quote("it's"), "'it'\\''s'");
  EXPECT_EQ(view::shell_quote(""), "''");
}

TEST(ViewCommand, BadFlagsAreRefused) {
  for (const auto& [args, message] : std::vector<std::pair<std::string, std::string>>{
           {"view --port 70000", "--port"},
           {"view --frames 3", "--frames: not for tracer view"},
           {"view --width 5000", "--width"},
           {"view --listen 256.1.1.1 --port 0", "cannot listen on 256.1.1.1"},
       }) {
    const test::CommandResult r = test::run_tracer(args);
    EXPECT_EQ(r.exit_code, 2) << args << ": " << r.output;
    EXPECT_NE(r.output.find(message), std::string::npos) << args << ": " << r.output;
  }
}

}  // namespace
}  // namespace tracer
