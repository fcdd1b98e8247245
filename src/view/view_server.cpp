#include "view/view_server.hpp"

#include <httplib.h>
#include <openssl/evp.h>
#include <nlohmann/json.hpp>

#include <cstdio>
#include <random>

#include "base/errors.hpp"
#include "io/exr_io.hpp"
#include "io/image_io.hpp"

namespace tracer::view {

namespace {

// The page, its script and style: src/view/page.html, embedded at build time.
constexpr const char kPage[] =
#include <view_page.inc>  // generated from src/view/page.html (CMakeLists.txt)
    ;

// A stream with nothing new sends a comment this often, so proxies and the browser keep it open
// and a closed tab is noticed.
constexpr auto kKeepAliveInterval = std::chrono::seconds(10);
// Server threads: the event streams hold one each, the other requests are short.
constexpr size_t kServerThreads = kMaxEventStreams + 8;

std::string base64(const std::string& bytes) {
  std::string out(4 * ((bytes.size() + 2) / 3) + 1, '\0');
  const int n = EVP_EncodeBlock(reinterpret_cast<unsigned char*>(out.data()),
                                reinterpret_cast<const unsigned char*>(bytes.data()), int(bytes.size()));
  out.resize(size_t(n));
  return out;
}

bool same_token(const std::string& given, const std::string& token) {
  if (given.size() != token.size()) return false;
  unsigned diff = 0;  // every character compared, so the time says nothing of the token
  for (size_t i = 0; i < token.size(); ++i) diff |= unsigned(given[i] ^ token[i]);
  return diff == 0;
}

void error_json(httplib::Response& res, int status, const std::string& message) {
  res.status = status;
  res.set_content(nlohmann::json{{"error", message}}.dump() + "\n", "application/json");
}

std::string frame_event(const Frame& f) {
  const nlohmann::json j = {{"seq", f.seq},
                            {"generation", f.generation},
                            {"width", f.width},
                            {"height", f.height},
                            {"spp", f.spp},
                            {"spp_target", f.spp_target},
                            {"pass_fraction", f.pass_fraction},
                            {"preview", f.preview},
                            {"complete", f.complete},
                            {"frame_ms", f.frame_ms},
                            {"msamples_per_s", f.msamples_per_s},
                            {"mrays_per_s", f.mrays_per_s},
                            {"mime", f.mime},
                            {"image", base64(f.bytes)}};
  return "event: frame\ndata: " + j.dump() + "\n\n";
}

}  // namespace

std::string random_token() {
  std::random_device device;
  std::string token;
  for (int i = 0; i < 4; ++i) {
    char part[9];
    std::snprintf(part, sizeof part, "%08x", unsigned(device()));
    token += part;
  }
  return token;
}

ViewServer::ViewServer(ViewSession& session, std::string token)
    : session_(session), token_(std::move(token)), server_(std::make_unique<httplib::Server>()) {
  server_->new_task_queue = [] { return new httplib::ThreadPool(kServerThreads); };
  server_->set_payload_max_length(kMaxControlBytes);
  server_->set_keep_alive_timeout(1);  // idle connections do not hold a stop back for long
  add_routes();
}

ViewServer::~ViewServer() { stop(); }

int ViewServer::bind(const std::string& host, int port) {
  const int bound = port == 0 ? server_->bind_to_any_port(host) : (server_->bind_to_port(host, port) ? port : -1);
  if (bound <= 0) {
    throw UsageError("--listen/--port: cannot listen on " + host + ":" + std::to_string(port) +
                     " (in use, or not an address of this machine; --port 0 picks a free port)");
  }
  return bound;
}

void ViewServer::listen() { server_->listen_after_bind(); }

void ViewServer::stop() {
  session_.frames().close();
  server_->stop();
}

void ViewServer::add_routes() {
  httplib::Server& s = *server_;
  s.set_pre_routing_handler([this](const httplib::Request& req, httplib::Response& res) {
    res.set_header("Cache-Control", "no-store");
    res.set_header("X-Content-Type-Options", "nosniff");
    if (!same_token(req.get_param_value("token"), token_)) {
      error_json(res, 403, "missing or wrong token: open the URL tracer view printed");
      return httplib::Server::HandlerResponse::Handled;
    }
    return httplib::Server::HandlerResponse::Unhandled;
  });
  s.set_error_handler([](const httplib::Request&, httplib::Response& res) {
    if (!res.body.empty()) return;
    const char* what = res.status == 413   ? "request body too large (at most 4096 bytes)"
                       : res.status == 404 ? "no such page"
                                           : "bad request";
    error_json(res, res.status, what);
  });
  s.set_exception_handler([](const httplib::Request&, httplib::Response& res, std::exception_ptr ep) {
    try {
      std::rethrow_exception(ep);
    } catch (const std::exception& e) {
      error_json(res, 500, std::string("internal error: ") + e.what());
    } catch (...) {
      error_json(res, 500, "internal error");
    }
  });

  s.Get("/", [](const httplib::Request&, httplib::Response& res) {
    // Nothing is loaded from elsewhere: the page's script and style are inline, its images data.
    res.set_header("Content-Security-Policy",
                   "default-src 'self'; script-src 'unsafe-inline'; style-src 'unsafe-inline'; "
                   "img-src 'self' data: blob:; frame-ancestors 'none'");
    res.set_content(kPage, sizeof kPage - 1, "text/html; charset=utf-8");
  });
  s.Get("/state", [this](const httplib::Request&, httplib::Response& res) {
    res.set_content(session_.state().dump() + "\n", "application/json");
  });
  s.Post("/control", [this](const httplib::Request& req, httplib::Response& res) {
    if (req.get_header_value("Content-Type").rfind("application/json", 0) != 0) {
      error_json(res, 415, "expected Content-Type: application/json");
      return;
    }
    nlohmann::json change;
    try {
      change = nlohmann::json::parse(req.body);
    } catch (const nlohmann::json::parse_error& e) {
      error_json(res, 400, std::string("not JSON: ") + e.what());
      return;
    }
    try {
      res.set_content(session_.apply(change).dump() + "\n", "application/json");
    } catch (const UsageError& e) {
      error_json(res, 400, e.what());
    } catch (const InputError& e) {
      error_json(res, 400, e.what());
    }
  });
  s.Get("/events", [this](const httplib::Request&, httplib::Response& res) {
    if (streams_.fetch_add(1) >= kMaxEventStreams) {
      streams_.fetch_sub(1);
      error_json(res, 503, "too many open viewers (at most " + std::to_string(kMaxEventStreams) + ")");
      return;
    }
    res.set_header("X-Accel-Buffering", "no");
    auto last = std::make_shared<uint64_t>(0);
    res.set_chunked_content_provider(
        "text/event-stream",
        [this, last](size_t, httplib::DataSink& sink) {
          // One frame per call, the newest: a slow reader blocks here in write and skips what it
          // missed, so nothing queues up for it.
          const std::shared_ptr<const Frame> frame = session_.frames().wait_newer(*last, kKeepAliveInterval);
          if (!frame) {
            if (session_.frames().closed()) return false;
            const std::string ping = ": keep-alive\n\n";
            return sink.write(ping.data(), ping.size());
          }
          *last = frame->seq;
          const std::string event = frame_event(*frame);
          return sink.write(event.data(), event.size());
        },
        [this](bool) { streams_.fetch_sub(1); });
  });
  const auto image = [this](bool exr) {
    return [this, exr](const httplib::Request&, httplib::Response& res) {
      const std::optional<ViewSession::Snapshot> snap = session_.snapshot();
      if (!snap) {
        error_json(res, 503, "no image yet: the first pass of this view is still rendering");
        return;
      }
      const std::string name = "tracer-" + std::to_string(snap->spp) + "spp" + (exr ? ".exr" : ".png");
      res.set_header("Content-Disposition", "attachment; filename=\"" + name + "\"");
      res.set_header("X-Samples-Per-Pixel", std::to_string(snap->spp));
      if (exr) {
        res.set_content(encode_exr(snap->radiance, ExrPixel::Float), "image/x-exr");
      } else {
        res.set_content(encode_png(snap->image), "image/png");
      }
    };
  };
  s.Get("/image.png", image(false));
  s.Get("/image.exr", image(true));
}

}  // namespace tracer::view
