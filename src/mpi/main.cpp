// tracer-mpi: `tracer render` over the ranks of an Open MPI job. Every rank loads the scene and
// builds its own accelerator; the scenes' checksums must agree; each pass's tiles are handed out
// on demand by rank 0 (mpi/tile_server.hpp) to every rank's render threads; rank 0 adds the
// returned tiles into its framebuffer, in the same order of passes as one process would, and
// writes the image, the checkpoints and the statistics. The image is byte-identical to
// `tracer render` with the same flags, for any number of ranks, threads and tile sizes.
// Exit codes as tracer's: 0, 1 bad input (on any rank), 2 bad usage, 128 + signal when stopped.
#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <exception>
#include <iostream>
#include <memory>
#include <mutex>
#include <new>
#include <optional>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "base/errors.hpp"
#include "base/stopwatch.hpp"
#include "driver/progress.hpp"
#include "driver/render_args.hpp"
#include "driver/render_driver.hpp"
#include "driver/render_stats.hpp"
#include "driver/signals.hpp"
#include "io/image_io.hpp"
#include "mpi/mpi_session.hpp"
#include "mpi/phase_watch.hpp"
#include "mpi/tile_server.hpp"
#include "parallel/parallel_pull.hpp"
#include "render/render_tile.hpp"
#include "scene/scene_checksum.hpp"

namespace tracer::mpi {
namespace {

// One line to stderr in one write, so lines from several ranks (and mpirun's own) never interleave.
void say(const std::string& line) { std::fputs((line + "\n").c_str(), stderr); }

// What one rank did, gathered on rank 0 for the statistics.
struct RankReport {
  uint64_t rays = 0;
  double idle_ms = 0, render_ms = 0;
};

// Everything every rank sets up before the first pass. `error` is empty when this rank is ready.
struct Setup {
  std::optional<Scene> scene;
  std::optional<Accelerator> accel;
  CameraSpec camera;
  RenderSettings settings;
  SchedOptions sched;
  int exit_code = 0;
  std::string error;
  double load_ms = 0;
  std::string fingerprint;  // settings_fingerprint(), once ready
};

// Every setting that changes a pixel or the tiles, one "flag value" line each, in a fixed order:
// ranks must agree on all of them (the scene itself is checksummed apart).
std::string settings_fingerprint(const Setup& s, const driver::RenderArgs& args) {
  std::ostringstream f;
  f.precision(9);
  const RenderSettings& r = s.settings;
  const auto vec = [](Vec3 v) {
    std::ostringstream o;
    o.precision(9);
    o << v.x << "," << v.y << "," << v.z;
    return o.str();
  };
  f << "--width " << r.width << "\n--height " << r.height << "\n--integrator "
    << name_of<Integrator>(kIntegratorNames, r.integrator) << "\n--spp " << r.spp << "\n--max-depth " << r.max_depth
    << "\n--ao " << r.ao_samples << "\n--ao-distance " << r.ao_distance << "\n--ambient " << r.ambient << "\n--seed "
    << r.seed << "\n--light-sampling " << name_of<LightSampling>(kLightSamplingNames, r.light_sampling)
    << "\n--env-map " << args.scene.env_map << "\n--env-rotation " << args.scene.env_rotation << "\n--env "
    << vec(r.environment) << "\n--eye " << vec(s.camera.eye) << "\n--look " << vec(s.camera.look) << "\n--up "
    << vec(s.camera.up) << "\n--fov " << s.camera.fov_degrees << "\n--frames " << args.frames << "\n--orbit "
    << args.orbit << "\n--checkpoint " << (args.checkpoint ? "on" : "off") << "\n--sched "
    << name_of<SchedKind>(kSchedKindNames, s.sched.kind) << "\n--tile " << s.sched.tile << "\n--block " << s.sched.block
    << "\n";
  return f.str();
}

// The first line of `theirs` that differs from `ours`, or "".
std::pair<std::string, std::string> first_difference(const std::string& ours, const std::string& theirs) {
  std::istringstream a(ours), b(theirs);
  for (std::string x, y; std::getline(a, x);) {
    if (!std::getline(b, y)) return {x, "(nothing)"};
    if (x != y) return {x, y};
  }
  return {};
}

Setup set_up(const driver::RenderArgs& args, const MpiSession& session) {
  Setup s;
  try {
    driver::validate(args);
    if (!args.aov.empty()) throw UsageError("--aov: not for tracer-mpi yet (tracer render writes the layers)");
    if (session.root()) driver::check_outputs(args);
    WideBvh::force_simd_target(driver::simd_target_for(args));
    const auto t0 = Clock::now();
    s.scene.emplace(driver::load_scene(args.scene, args.quiet || !session.root()));
    s.load_ms = ms_since(t0);
    if (session.root()) driver::check_outputs_against_inputs(args);
    s.camera = driver::camera_for(*s.scene, args);
    std::string note;
    s.settings = driver::settings_for(args, *s.scene, note);
    if (!note.empty() && !args.quiet && session.root()) say("tracer-mpi: note: " + note);
    s.sched = driver::sched_options_for(args);
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
    AccelOptions accel_options = driver::accel_options_for(args);
    s.accel.emplace(build_accelerator(*s.scene, accel_options));
  } catch (const UsageError& e) {
    s.exit_code = 2;
    s.error = e.what();
  } catch (const std::bad_alloc&) {
    s.exit_code = 1;
    s.error = "out of memory";
  } catch (const std::exception& e) {
    s.exit_code = 1;
    s.error = e.what();
  }
  return s;
}

// The passes each round of tile distribution covers (driver::rounds_of): with --checkpoint, one
// round per pass, so rank 0 has every pass complete in turn; without, one round of every pass:
// each tile is rendered whole (its passes in order, adding up exactly as one process adds them)
// and crosses the network once, so rank 0 adds each pixel once instead of once per pass.

// Renders the passes of `round` of one tile, in order, into `fb` (rank 0's image, or a window for
// the tile).
RayCounts render_one(const Accelerator& accel, const RenderContext& ctx, const std::vector<SampleRange>& round,
                     Framebuffer& fb, const Tile& tile) {
  RenderContext c = ctx;
  c.framebuffer = &fb;
  RayCounts counts;
  for (const SampleRange& pass : round) {
    c.samples = pass;
    counts += accel.visit([&](const auto& a) { return render_tile(a, c, tile); });
  }
  return counts;
}

// mpirun answers Ctrl-C, and the death of any rank, by sending SIGTERM to every rank: a rank
// cannot tell which happened, and its peers may already be gone, so each stops at once. Rank 0
// says so in one line; no image is written (a --checkpoint written before stays: it is complete).
constexpr const char* kStopMessage =
    "tracer-mpi: rank 0 stopped by a signal (mpirun sends it on Ctrl-C and when another rank fails: see its "
    "message); no image written\n";

// `parse_error`: this rank's flags did not parse (exit code 2 and the message); it still joins the
// first collective, so rank 0 can name it and end the job instead of waiting for it.
int run(const driver::RenderArgs& args, MpiSession& session, const std::string& parse_error, double rank_timeout,
        PhaseWatch& watch_phase) {
  driver::install_immediate_stop_handlers(session.root() ? kStopMessage : nullptr);
  const ThreadLimit thread_limit(args.threads.value_or(0));
  // Built in place, never moved: the accelerator points into the scene.
  Setup setup = parse_error.empty() ? set_up(args, session) : Setup{};
  if (!parse_error.empty()) {
    setup.exit_code = 2;
    setup.error = parse_error;
  }
  if (setup.error.empty()) setup.fingerprint = settings_fingerprint(setup, args);

  // Every rank's readiness and scene checksum, judged on rank 0, which says what is wrong once.
  const std::vector<std::string> errors =
      session.gather_strings(setup.error.empty() ? "" : std::to_string(setup.exit_code) + " " + setup.error);
  const std::vector<uint64_t> checksums = session.all_gather(setup.error.empty() ? scene_checksum(*setup.scene) : 0);
  const std::vector<uint64_t> environments =
      session.all_gather(setup.error.empty() ? environment_checksum(setup.scene->environment_map) : 0);
  const int threads = setup.error.empty() ? thread_count(setup.sched) : 0;
  const std::vector<uint64_t> all_threads = session.all_gather(uint64_t(threads));
  const std::vector<std::string> fingerprints = session.gather_strings(setup.fingerprint);
  int verdict = 0;
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
  watch_phase.disarm();  // start-up is over: every rank answered
  if (verdict != 0) {
    // The first rank to exit non-zero makes mpirun stop the others with SIGTERM: rank 0 has said
    // what is wrong, so that signal needs no second message.
    driver::install_immediate_stop_handlers(nullptr);
    return verdict;
  }

  const Scene& scene = *setup.scene;
  const Accelerator& accel = *setup.accel;
  const RenderSettings& settings = setup.settings;
  const std::vector<Tile> tiles = tiles_for(settings.width, settings.height, setup.sched);
  StallWatch watch;
  watch.floor_seconds = rank_timeout;

  RankReport mine;
  double server_ms = 0;  // rank 0: time spent on messages (requests, returned tiles, done)
  uint64_t served = 0;   // rank 0: messages handled
  AtomicRayCounts counts;
  std::atomic<uint64_t> pixels_done{0}, rays_done{0};
  std::vector<uint64_t> tiles_per_rank(size_t(session.size()), 0);
  const auto t_render = Clock::now();
  std::optional<driver::ProgressBar> progress;
  if (session.root()) {
    const uint64_t work =
        uint64_t(settings.width) * uint64_t(settings.height) * uint64_t(settings.spp) * uint64_t(args.frames);
    progress.emplace(!args.quiet, work, pixels_done, rays_done);
  }
  std::mutex report_mutex;
  std::atomic<double> slowest_tile_s{0.0};  // this rank's slowest tile so far
  uint32_t round_serial = 0;                // rounds over all frames, for their messages' tags
  const auto render_round = [&](const RenderContext& ctx, const std::vector<SampleRange>& round) {
    ++round_serial;
    const uint32_t first = round.front().first, samples = round.back().first + round.back().count - first;
    const auto count = [&](const RayCounts& c, const Tile& t) {
      counts.add(c);
      rays_done.fetch_add(c.total(), std::memory_order_relaxed);
      pixels_done.fetch_add(uint64_t(t.pixel_count()) * samples, std::memory_order_relaxed);
    };
    if (session.root()) {
      Framebuffer& fb = *ctx.framebuffer;
      TileServer server(tiles, all_threads, round_serial, watch);
      std::exception_ptr own_failure;
      std::thread own([&] {
        try {
          parallel_pull(
              threads, [&] { return server.take(); },
              [&](const TileGrant& g) {
                const Tile& t = tiles[g.tile];
                if (!g.reissued) {
                  count(render_one(accel, ctx, round, fb, t), t);
                  server.own_done(g.tile);
                  return;
                }
                // Taken back from a late rank: its copy may still come, so render apart.
                Framebuffer window(t);
                count(render_one(accel, ctx, round, window, t), t);
                server.commit(g.tile, window, fb, samples);
              });
        } catch (...) {
          own_failure = std::current_exception();
        }
      });
      try {
        server.serve(fb, samples);
      } catch (const RankFailed& e) {
        if (progress) progress->stop();
        say("tracer-mpi: error: rank " + std::to_string(e.rank) + " of " + std::to_string(session.size()) + ": " +
            e.what() + "; no image written");
        MPI_Abort(MPI_COMM_WORLD, 1);
      }
      own.join();
      if (own_failure) std::rethrow_exception(own_failure);  // main() reports it and aborts the job
      server_ms += server.busy_ms();
      served += server.messages();
      const std::vector<uint64_t> given = server.tiles_per_rank();
      for (size_t r = 0; r < given.size(); ++r) tiles_per_rank[r] += given[r];
      return true;
    }
    TileClient client(tiles, round_serial);
    // Rank 0 answers a request at once, or, between rounds, once the round is in: within the time
    // it gives a late rank (overdue_after()) and the rendering of that rank's tiles. Twice that
    // without an answer, rank 0 itself has stopped.
    const auto answer_bound = [&] { return 2.0 * std::max(rank_timeout, 8.0 * slowest_tile_s.load()); };
    watch_phase.arm("tracer-mpi: error: rank " + std::to_string(session.rank()) + " of " +
                        std::to_string(session.size()) + ": rank 0 stopped answering (no answer within " +
                        std::to_string(int(answer_bound())) + " s); ending the job",
                    answer_bound());
    try {
      // Each thread renders its tiles into windows of its own and sends them back; its next
      // request is already in flight while it renders.
      std::atomic<int> thread_ids{0};
      parallel_run(threads, [&] {
        TileClient::Worker worker(client, thread_ids.fetch_add(1));
        std::optional<uint32_t> finished;
        std::unique_ptr<Framebuffer> result;
        double idle = 0;
        while (const std::optional<uint32_t> next = worker.next(finished, result.get(), idle)) {
          const Tile& t = tiles[*next];
          result = std::make_unique<Framebuffer>(t);
          const auto t0 = Clock::now();
          count(render_one(accel, ctx, round, *result, t), t);
          const double took = ms_since(t0) * 1e-3;
          for (double seen = slowest_tile_s.load(); took > seen && !slowest_tile_s.compare_exchange_weak(seen, took);) {
          }
          watch_phase.progress(answer_bound());
          finished = *next;
        }
        std::lock_guard lock(report_mutex);
        mine.idle_ms += idle;
      });
    } catch (const std::exception& e) {
      TileClient::report_failure(e.what());
      for (;;) std::this_thread::sleep_for(std::chrono::seconds(1));  // rank 0 aborts the job
    }
    return true;
  };
  // Signals end a rank at once (install_immediate_stop_handlers): no round is ever stopped.
  const driver::FrameSequence frames{args.output, args.frames, args.orbit, args.checkpoint, driver::exr_pixel_for(args),
                                     false};
  const driver::DriveResult driven =
      driver::drive_render(scene, setup.camera, settings, frames, session.root(), args.checkpoint.has_value(), nullptr,
                           render_round, [](const std::string& w) { say("tracer-mpi: warning: " + w); });
  const int checkpoints = driven.checkpoints;
  if (session.root()) {
    const auto ranks = [&](const std::vector<int>& list) {
      std::string text;
      for (const int r : list) text += (text.empty() ? "" : ", ") + std::to_string(r);
      return text;
    };
    if (!watch.recovered.empty()) {
      say("tracer-mpi: warning: rank " + ranks(watch.recovered) + " of " + std::to_string(session.size()) +
          " was late (a tile out for more than " + std::to_string(int(watch.overdue_after())) +
          " s); its tiles were also rendered by others, the first copy kept");
    }
    if (!watch.gone.empty()) {
      // The image is complete and written; the silent rank cannot join the statistics, so the
      // job ends here, with its runtime told to stop every rank.
      if (progress) progress->stop();
      say("tracer-mpi: error: rank " + ranks(watch.gone) + " of " + std::to_string(session.size()) +
          " stopped answering (no tile back within " + std::to_string(int(watch.overdue_after())) +
          " s); the other ranks rendered its tiles and the image was written; ending the job");
      driver::install_immediate_stop_handlers(nullptr);  // the runtime's SIGTERM needs no second message
      MPI_Abort(MPI_COMM_WORLD, 1);
    }
  }
  if (progress) progress->stop();
  mine.render_ms = ms_since(t_render);
  // The statistics: every rank answers once rank 0 has written the image.
  const double gather_bound = 2.0 * std::max(rank_timeout, 8.0 * slowest_tile_s.load()) + 60.0;
  watch_phase.arm("tracer-mpi: error: rank " + std::to_string(session.rank()) + " of " +
                      std::to_string(session.size()) + ": the ranks' statistics did not arrive within " +
                      std::to_string(int(gather_bound)) + " s (a rank stopped answering); ending the job",
                  gather_bound);
  mine.rays = counts.load().total();

  // Statistics: every rank's tiles, rays and idle time, on rank 0.
  const RayCounts own_counts = counts.load();
  RayCounts total;
  for (const auto& [field, value] : {std::pair{&RayCounts::primary, own_counts.primary},
                                     {&RayCounts::shadow, own_counts.shadow},
                                     {&RayCounts::ao, own_counts.ao},
                                     {&RayCounts::secondary, own_counts.secondary}}) {
    for (uint64_t v : session.all_gather(value)) total.*field += v;
  }
  const std::vector<uint64_t> rays = session.all_gather(mine.rays);
  const std::vector<uint64_t> idle_us = session.all_gather(uint64_t(mine.idle_ms * 1e3));
  const std::vector<uint64_t> render_us = session.all_gather(uint64_t(mine.render_ms * 1e3));
  watch_phase.disarm();
  if (session.root()) {
    nlohmann::json stats =
        driver::render_stats(scene, settings, accel, setup.sched, args, setup.load_ms, mine.render_ms, total);
    uint64_t all_rays = 0;
    nlohmann::json ranks = nlohmann::json::array();
    for (int r = 0; r < session.size(); ++r) {
      all_rays += rays[size_t(r)];
      ranks.push_back({{"rank", r},
                       {"threads", all_threads[size_t(r)]},
                       {"tiles", tiles_per_rank[size_t(r)]},
                       {"rays", rays[size_t(r)]},
                       {"idle_ms", double(idle_us[size_t(r)]) * 1e-3},
                       {"render_ms", double(render_us[size_t(r)]) * 1e-3}});
    }
    stats["ranks"] = ranks;
    stats["tiles_per_pass"] = tiles.size();
    stats["passes"] = sample_passes(settings).size() * size_t(args.frames);
    stats["rounds"] = round_serial;  // rounds of tile distribution (one per pass with --checkpoint)
    stats["rays"]["total"] = all_rays;
    stats["mrays_per_s"] = mine.render_ms > 0 ? double(all_rays) / (mine.render_ms * 1e3) : 0.0;
    stats["checkpoints_written"] = checkpoints;
    stats["rank0_message_ms"] = server_ms;
    stats["rank0_messages"] = served;
    stats["rank0_us_per_message"] = served > 0 ? server_ms * 1e3 / double(served) : 0.0;
    if (args.stats) {
      driver::print_stats(stats, accel);
      std::printf("rank 0       %.1f ms on %llu messages (%.1f us each)\n", server_ms, (unsigned long long)served,
                  served > 0 ? server_ms * 1e3 / double(served) : 0.0);
      for (const auto& r : ranks) {
        std::printf("rank %-6d %d threads, %llu tiles, %llu rays, idle %.1f ms\n", r["rank"].get<int>(),
                    r["threads"].get<int>(), (unsigned long long)r["tiles"].get<uint64_t>(),
                    (unsigned long long)r["rays"].get<uint64_t>(), r["idle_ms"].get<double>());
      }
    }
    driver::write_stats_json(args.stats_json, stats);
  }
  return 0;
}

}  // namespace
}  // namespace tracer::mpi

int main(int argc, char** argv) {
  using namespace tracer;
  // Start-up (MPI's, the scene's loading, the agreement on the setup) has a bound of its own from
  // the first instant, MPI_Init included: a rank that never gets there ends the job, named.
  double startup_timeout = 120.0;
  for (int i = 1; i + 1 < argc; ++i) {
    if (std::string(argv[i]) == "--startup-timeout") startup_timeout = std::atof(argv[i + 1]);
  }
  if (!(startup_timeout >= 0.1 && startup_timeout <= 1e6)) startup_timeout = 120.0;  // CLI11 says what is wrong
  mpi::PhaseWatch watch;
  watch.arm("tracer-mpi: error: rank " + mpi::launcher_rank_text() + ": start-up did not end within " +
                std::to_string(int(startup_timeout)) +
                " s (MPI start-up, loading the scene, agreeing on the setup): a rank stopped or cannot be reached "
                "(--startup-timeout raises it); ending the job",
            startup_timeout);
  std::optional<mpi::MpiSession> session;
  try {
    session.emplace(argc, argv);
  } catch (const std::exception& e) {
    tracer::mpi::say(std::string("tracer-mpi: error: ") + e.what());
    return 1;
  }
  CLI::App app{"tracer-mpi: tracer render over the ranks of an Open MPI job (mpirun -np N tracer-mpi render ...)"};
  app.require_subcommand(1);
  driver::RenderArgs args;
  CLI::App* render = app.add_subcommand("render", "render a scene to a PNG, PPM or OpenEXR image, on every rank");
  driver::add_render_options(*render, args);
  driver::file_option(render->add_option("-o,--output", args.output, "output image (written by rank 0)"))
      ->capture_default_str();
  render->add_flag("--stats", args.stats, "print timings, ray counts and each rank's tiles, rays and idle time");
  driver::file_option(render->add_option("--stats-json", args.stats_json,
                                         "write the statistics as JSON to this file (rank 0; '-': standard output)"));
  render->add_flag("-q,--quiet", args.quiet, "no progress bar, no loader warnings");
  double rank_timeout = mpi::StallWatch{}.floor_seconds;
  render
      ->add_option("--rank-timeout", rank_timeout,
                   "seconds a tile may be out with a rank before its tiles go to others (at least; 8x the slowest "
                   "tile so far if more)")
      ->check(CLI::Range(0.1, 1e6))
      ->capture_default_str();
  render
      ->add_option("--startup-timeout", startup_timeout,
                   "seconds every rank may take to start, load the scene and agree on the setup")
      ->check(CLI::Range(0.1, 1e6))
      ->capture_default_str();
  std::string parse_error;
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return session->root() ? app.exit(e) : 0;
    parse_error = std::string(e.what()) + " (see tracer-mpi --help)";
  }
  try {
    return mpi::run(args, *session, parse_error, rank_timeout, watch);
  } catch (const std::exception& e) {
    mpi::say("tracer-mpi: error: rank " + std::to_string(session->rank()) + ": " + e.what());
    MPI_Abort(MPI_COMM_WORLD, 1);
  }
  return 1;
}
