// Start-up of a tracer-mpi job: each rank prepares its render (the same steps as tracer render),
// then the ranks agree that they loaded the same scene and environment and render with the same
// settings, judged on rank 0, which says once what is wrong.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "frontend/prepare_render.hpp"
#include "mpi/mpi_session.hpp"

namespace tracer::mpi {

// One line to stderr in one write, so lines from several ranks (and mpirun's own) never interleave.
void say(const std::string& line);

// This rank's setup. `error` is empty when it is ready; else exit_code says why (1 input, 2 usage).
struct RankSetup {
  std::optional<frontend::PreparedRender> prepared;
  int exit_code = 0;
  std::string error;
  std::string fingerprint;  // settings_fingerprint(), once ready
};

// Prepares this rank's render into `setup`, catching what goes wrong: every rank must still join
// the agreement, so rank 0 can name the rank and end the job instead of waiting for it.
void set_up(RankSetup& setup, const frontend::RenderArgs& args, const MpiSession& session);

// Every setting that changes a pixel or the tiles, one "flag value" line each, in a fixed order:
// ranks must agree on all of them (the scene itself is checksummed apart).
std::string settings_fingerprint(const frontend::PreparedRender& prepared, const frontend::RenderArgs& args);

struct Agreement {
  int verdict = 0;                // 0: every rank is ready and alike; else the job's exit code
  std::vector<uint64_t> threads;  // each rank's render threads
};

// Collective: every rank's readiness, scene and environment checksums, threads and settings,
// judged on rank 0 (which says what is wrong, once), the verdict broadcast to all.
Agreement agree_on_setup(const RankSetup& setup, const frontend::RenderArgs& args, const MpiSession& session);

}  // namespace tracer::mpi
