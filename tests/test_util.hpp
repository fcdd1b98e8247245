// Shared helpers for the tests: scene paths, random rays, running the CLI, image comparison.
#pragma once

#include <cstdint>
#include <initializer_list>
#include <string>
#include <string_view>
#include <vector>

#include "film/tone_map.hpp"
#include "math/ray.hpp"
#include "scene/scene.hpp"

namespace tracer::test {

std::string scene_path(const std::string& relative);  // under ../shared/scenes
bool have_shared_scenes();

// Deterministic random rays: origins in the scene's box grown by 20%, uniform directions.
std::vector<Ray> random_rays(const Scene& scene, size_t count, uint32_t seed);

// How many rays a test should trace: TRACER_TEST_RAYS overrides `dflt` (sanitizer runs lower it).
size_t ray_budget(size_t dflt);

// Whether the tests (and the binaries they run) are built with a sanitizer: memory and time are
// then the sanitizer's (shadow memory, a quarantine, slower threads), so a test that bounds them
// skips that bound.
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
inline constexpr bool kUnderSanitizer = true;
#else
inline constexpr bool kUnderSanitizer = false;
#endif

struct CommandResult {
  int exit_code;
  std::string output;  // stdout and stderr together
};
// Runs the tracer binary with `args` (shell-quoted by the caller).
CommandResult run_tracer(const std::string& args);
// A shell command (sh -c), its stdout and stderr together.
CommandResult run_shell(const std::string& command);

// A scene of loose triangles, one geometry, default material, finalized.
Scene scene_of(const std::vector<Triangle>& tris);

double psnr(const Image8& a, const Image8& b);

// The upper tail probability of Pearson's chi-square statistic of `observed` counts against
// `expected` ones (cells expecting fewer than 5 pooled into one), by Wilson and Hilferty's normal
// approximation: small when the counts do not follow the expectation.
double chi_square_tail(const std::vector<double>& observed, const std::vector<double>& expected);

// A fresh temporary directory for one test.
std::string temp_dir();
// Every byte of a file (images compared byte for byte).
std::string read_bytes(const std::string& path);

// The one-line error of loading glTF text `json` as "t.gltf", or "(loaded)".
std::string gltf_load_error(const std::string& json);
// Base64 of `bytes` (a glTF data: URI's payload).
std::string base64(std::string_view bytes);
// The bytes of `values` as stored in memory (a glTF buffer's contents).
template <class T>
std::string bytes_of(std::initializer_list<T> values) {
  std::string s;
  for (T v : values) s.append(reinterpret_cast<const char*>(&v), sizeof v);
  return s;
}

}  // namespace tracer::test
