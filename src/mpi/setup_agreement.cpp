#include "mpi/setup_agreement.hpp"

#include <algorithm>
#include <cstdio>
#include <exception>
#include <new>
#include <sstream>
#include <thread>

#include "base/errors.hpp"
#include "frontend/settings_table.hpp"
#include "parallel/thread_count.hpp"
#include "scene/camera.hpp"
#include "scene/scene_checksum.hpp"

namespace tracer::mpi {

void say(const std::string& line) { std::fputs((line + "\n").c_str(), stderr); }

namespace {

// The first line of `theirs` that differs from `ours`, or "".
std::pair<std::string, std::string> first_difference(const std::string& ours, const std::string& theirs) {
  std::istringstream a(ours), b(theirs);
  for (std::string x, y; std::getline(a, x);) {
    if (!std::getline(b, y)) return {x, "(nothing)"};
    if (x != y) return {x, y};
  }
  return {};
}

}  // namespace

std::string settings_fingerprint(const frontend::PreparedRender& s, const frontend::RenderArgs& args) {
  // Every flag that defines the image or cuts the work, as given; then what they resolve to on
  // this rank (a views file or a glTF camera may differ between nodes).
  std::ostringstream f;
  f.precision(9);
  const auto vec = [](Vec3 v) {
    std::ostringstream o;
    o.precision(9);
    o << v.x << "," << v.y << "," << v.z;
    return o.str();
  };
  const RenderSettings& r = s.settings;
  f << frontend::settings_lines(args, {frontend::Role::Image, frontend::Role::Work}) << "camera " << vec(s.camera.eye)
    << " " << vec(s.camera.look) << " " << vec(s.camera.up) << " " << s.camera.fov_degrees << " "
    << s.camera.lens_radius << " " << Camera(s.camera, r.width, r.height).focus_distance() << "\nenvironment "
    << vec(r.environment) << "\nsamples " << r.spp << " noise threshold " << r.noise_threshold << "\n";
  return f.str();
}

void set_up(RankSetup& s, const frontend::RenderArgs& args, const MpiSession& session) {
  try {
    if (!args.aov.empty()) throw UsageError("--aov: not for tracer-mpi yet (tracer render writes the layers)");
    s.prepared.emplace(
        args, frontend::PrepareOptions{
                  .writes_outputs = session.root(), .quiet = args.quiet || !session.root(), .cancel = nullptr});
    const std::string& note = s.prepared->lighting_note;
    if (!note.empty() && !args.quiet && session.root()) say("tracer-mpi: note: " + note);
    const int usable = resolve_thread_count(0);
    const int machine = int(std::thread::hardware_concurrency());
    if (args.threads && *args.threads > usable && usable < machine) {
      // Open MPI binds each rank to a core when there are two ranks or fewer: a hybrid run then
      // time-shares that core. Each affected rank says so (nodes may differ).
      const std::string line = "tracer-mpi: warning: rank " + std::to_string(session.rank()) + " may use " +
                               std::to_string(usable) + " of this node's " + std::to_string(machine) +
                               " CPUs for its " + std::to_string(*args.threads) +
                               " threads (mpirun binds ranks to cores: add --bind-to none, or --map-by "
                               "ppr:1:node:PE=" +
                               std::to_string(*args.threads) + ")\n";
      std::fputs(line.c_str(), stderr);  // one write: the ranks' lines do not interleave
    }
    s.fingerprint = settings_fingerprint(*s.prepared, args);
  } catch (...) {
    const Failure f = failure_of(std::current_exception());
    s.exit_code = f.exit_code;
    s.error = f.message;
  }
}

Agreement agree_on_setup(const RankSetup& setup, const frontend::RenderArgs& args, const MpiSession& session) {
  // Every rank's readiness and scene checksum, judged on rank 0, which says what is wrong once.
  const std::vector<std::string> errors =
      session.gather_strings(setup.error.empty() ? "" : std::to_string(setup.exit_code) + " " + setup.error);
  const std::vector<uint64_t> checksums =
      session.all_gather(setup.error.empty() ? scene_checksum(setup.prepared->scene) : 0);
  const std::vector<uint64_t> environments =
      session.all_gather(setup.error.empty() ? environment_checksum(setup.prepared->scene.environment_map) : 0);
  const int threads = setup.error.empty() ? thread_count(setup.prepared->sched) : 0;
  Agreement agreement;
  agreement.threads = session.all_gather(uint64_t(threads));
  const std::vector<std::string> fingerprints = session.gather_strings(setup.fingerprint);
  int& verdict = agreement.verdict;
  if (session.root()) {
    const bool same_everywhere =
        std::all_of(errors.begin(), errors.end(), [&](const std::string& e) { return e == errors[0]; });
    for (int r = 0; r < session.size() && verdict == 0; ++r) {
      const std::string& e = errors[size_t(r)];
      if (e.empty()) continue;
      const size_t space = e.find(' ');
      verdict = std::stoi(e.substr(0, space));
      const std::string what = e.substr(space + 1);
      if (verdict == 2 && same_everywhere) {
        say("tracer-mpi: error: " + what);  // the same flags on every rank
      } else {
        say("tracer-mpi: error: rank " + std::to_string(r) + " of " + std::to_string(session.size()) + ": " + what);
      }
    }
    for (int r = 1; r < session.size() && verdict == 0; ++r) {
      if (checksums[size_t(r)] != checksums[0]) {
        char text[64];
        std::snprintf(text, sizeof text, "%016llx, rank 0's %016llx", (unsigned long long)checksums[size_t(r)],
                      (unsigned long long)checksums[0]);
        say("tracer-mpi: error: rank " + std::to_string(r) + " loaded different scene contents than rank 0 (checksum " +
            text + "): every rank must read the same scene files");
        verdict = 1;
      }
    }
    for (int r = 1; r < session.size() && verdict == 0; ++r) {
      if (environments[size_t(r)] != environments[0]) {
        say("tracer-mpi: error: rank " + std::to_string(r) + " of " + std::to_string(session.size()) +
            " read a different environment map than rank 0 (--env-map '" + args.scene.env_map +
            "' on rank 0): every rank must read the same file, or none");
        verdict = 1;
      }
    }
    // After the scene: another scene frames another default camera.
    for (int r = 1; r < session.size() && verdict == 0; ++r) {
      const auto [ours, theirs] = first_difference(fingerprints[0], fingerprints[size_t(r)]);
      if (ours.empty()) continue;
      say("tracer-mpi: error: rank " + std::to_string(r) + " of " + std::to_string(session.size()) + " renders with " +
          theirs + ", rank 0 with " + ours + ": every rank must be given the same render settings");
      verdict = 2;
    }
  }
  verdict = session.broadcast(verdict);
  return agreement;
}

}  // namespace tracer::mpi
