#include "test_util.hpp"

#include <sys/wait.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>

#include "importers/gltf_loader.hpp"
#include "math/rng.hpp"

namespace tracer::test {

std::string scene_path(const std::string& relative) { return std::string(TRACER_SCENES_DIR) + "/" + relative; }

bool have_shared_scenes() { return std::filesystem::exists(scene_path("cornell-box/CornellBox-Original.obj")); }

size_t ray_budget(size_t dflt) {
  if (const char* env = std::getenv("TRACER_TEST_RAYS")) return std::max<size_t>(1, std::strtoull(env, nullptr, 10));
  return dflt;
}

std::vector<Ray> random_rays(const Scene& scene, size_t count, uint32_t seed) {
  std::vector<Ray> rays(count);
  const Vec3 lo = scene.bounds.lo - scene.bounds.extent() * 0.2f;
  const Vec3 ext = scene.bounds.extent() * 1.4f;
  for (size_t i = 0; i < count; ++i) {
    const SampleRng rng(uint32_t(i), 0, seed);
    Ray& r = rays[i];
    r.org = lo + Vec3{rng.draw(0) * ext.x, rng.draw(1) * ext.y, rng.draw(2) * ext.z};
    const float z = 1.0f - 2.0f * rng.draw(3), phi = 6.2831853f * rng.draw(4);
    const float s = std::sqrt(std::max(0.0f, 1.0f - z * z));
    r.dir = {s * std::cos(phi), s * std::sin(phi), z};
  }
  return rays;
}

CommandResult run_tracer(const std::string& args) { return run_shell(std::string(TRACER_EXE) + " " + args); }

CommandResult run_shell(const std::string& command) {
  const std::string cmd = command + " 2>&1";
  FILE* pipe = ::popen(cmd.c_str(), "r");
  CommandResult result{-1, ""};
  if (!pipe) return result;
  std::array<char, 4096> buf;
  size_t n;
  while ((n = std::fread(buf.data(), 1, buf.size(), pipe)) > 0) result.output.append(buf.data(), n);
  const int status = ::pclose(pipe);
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  return result;
}

Scene scene_of(const std::vector<Triangle>& tris) {
  Scene s;
  s.source = "test";
  s.materials.push_back(Material{});
  std::vector<Vec3> v;
  std::vector<uint32_t> idx;
  for (const Triangle& t : tris) {
    for (const Vec3& p : {t.v0, t.v1, t.v2}) {
      idx.push_back(uint32_t(v.size()));
      v.push_back(p);
    }
  }
  s.add_mesh("tris", v, idx, 0);
  s.finalize();
  return s;
}

double psnr(const Image8& a, const Image8& b) {
  if (a.width != b.width || a.height != b.height) return 0.0;
  double mse = 0.0;
  for (size_t i = 0; i < a.rgb.size(); ++i) {
    const double d = double(a.rgb[i]) - double(b.rgb[i]);
    mse += d * d;
  }
  mse /= double(a.rgb.size());
  return mse == 0.0 ? 1e9 : 10.0 * std::log10(255.0 * 255.0 / mse);
}

std::string gltf_load_error(const std::string& json) {
  try {
    load_gltf_from_memory(json, "t.gltf", [](const std::string&) {});
  } catch (const InputError& e) {
    return e.what();
  }
  return "(loaded)";
}

std::string base64(std::string_view bytes) {
  static const char* k = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  for (size_t i = 0; i < bytes.size(); i += 3) {
    uint32_t v = uint32_t(uint8_t(bytes[i])) << 16;
    if (i + 1 < bytes.size()) v |= uint32_t(uint8_t(bytes[i + 1])) << 8;
    if (i + 2 < bytes.size()) v |= uint32_t(uint8_t(bytes[i + 2]));
    out += k[(v >> 18) & 63];
    out += k[(v >> 12) & 63];
    out += i + 1 < bytes.size() ? k[(v >> 6) & 63] : '=';
    out += i + 2 < bytes.size() ? k[v & 63] : '=';
  }
  return out;
}

std::string read_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

std::string temp_dir() {
  std::string tmpl = (std::filesystem::temp_directory_path() / "tracer-test-XXXXXX").string();
  if (!::mkdtemp(tmpl.data())) std::abort();
  return tmpl;
}

double chi_square_tail(const std::vector<double>& observed, const std::vector<double>& expected) {
  double chi2 = 0.0, pooled_obs = 0.0, pooled_exp = 0.0;
  int cells = 0;
  for (size_t i = 0; i < observed.size(); ++i) {
    if (expected[i] < 5.0) {
      pooled_obs += observed[i];
      pooled_exp += expected[i];
      continue;
    }
    chi2 += (observed[i] - expected[i]) * (observed[i] - expected[i]) / expected[i];
    ++cells;
  }
  if (pooled_exp > 0.0) {
    chi2 += (pooled_obs - pooled_exp) * (pooled_obs - pooled_exp) / pooled_exp;
    ++cells;
  }
  const double k = std::max(cells - 1, 1);
  const double z = (std::cbrt(chi2 / k) - (1.0 - 2.0 / (9.0 * k))) / std::sqrt(2.0 / (9.0 * k));
  return 0.5 * std::erfc(z / std::sqrt(2.0));
}

}  // namespace tracer::test
