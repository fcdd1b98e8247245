#include "view/view_server.hpp"

#include <httplib.h>
#include <openssl/evp.h>
#include <nlohmann/json.hpp>

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <random>
#include <thread>

#include "base/errors.hpp"
#include "io/exr_io.hpp"
#include "io/image_io.hpp"
#include "view/connection_guard.hpp"

namespace tracer::view {

namespace {

// The two downloads of the current image: tone-mapped PNG, or linear EXR.
enum class ImageFile { Png, Exr };

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

void error_json(httplib::Response& res, int status, const std::string& message) {
  res.status = status;
  res.set_content(nlohmann::json{{"error", message}}.dump() + "\n", "application/json");
}

using Clock = std::chrono::steady_clock;

int ms_until(Clock::time_point deadline) {
  return int(
      std::max<int64_t>(0, std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now()).count()));
}

// A connection as cpp-httplib's Stream: reads and writes wait at most their timeouts.
class ConnectionStream : public httplib::Stream {
 public:
  explicit ConnectionStream(int sock) : sock_(sock) {}
  bool is_readable() const override { return wait(POLLIN, kIoTimeoutMs); }
  bool is_writable() const override { return wait(POLLOUT, kIoTimeoutMs); }
  ssize_t read(char* ptr, size_t size) override {
    if (!wait(POLLIN, kIoTimeoutMs)) return -1;
    return ::recv(sock_, ptr, size, 0);
  }
  ssize_t write(const char* ptr, size_t size) override {
    if (!wait(POLLOUT, kIoTimeoutMs)) return -1;
    return ::send(sock_, ptr, size, MSG_NOSIGNAL);
  }
  void get_remote_ip_and_port(std::string& ip, int& port) const override { address(true, ip, port); }
  void get_local_ip_and_port(std::string& ip, int& port) const override { address(false, ip, port); }
  socket_t socket() const override { return sock_; }

  bool wait(short events, int timeout_ms) const {
    pollfd p{sock_, events, 0};
    return ::poll(&p, 1, timeout_ms) > 0 && (p.revents & (events | POLLHUP)) != 0;
  }

 private:
  static constexpr int kIoTimeoutMs = 5000;
  void address(bool remote, std::string& ip, int& port) const {
    sockaddr_storage addr{};
    socklen_t len = sizeof addr;
    const int ok = remote ? ::getpeername(sock_, reinterpret_cast<sockaddr*>(&addr), &len)
                          : ::getsockname(sock_, reinterpret_cast<sockaddr*>(&addr), &len);
    char text[INET6_ADDRSTRLEN] = "";
    port = 0;
    if (ok == 0 && addr.ss_family == AF_INET) {
      const auto* a = reinterpret_cast<const sockaddr_in*>(&addr);
      ::inet_ntop(AF_INET, &a->sin_addr, text, sizeof text);
      port = ntohs(a->sin_port);
    } else if (ok == 0 && addr.ss_family == AF_INET6) {
      const auto* a = reinterpret_cast<const sockaddr_in6*>(&addr);
      ::inet_ntop(AF_INET6, &a->sin6_addr, text, sizeof text);
      port = ntohs(a->sin6_port);
    }
    ip = text;
  }
  int sock_;
};

// The head of the next request, peeked (left in the socket for cpp-httplib to read), ending in
// its blank line; empty if the client sent nothing before `first_byte` or closed, or its head did
// not end within kHeadDeadline of its first byte (or kMaxHeadBytes).
std::string peek_head(const ConnectionStream& stream, Clock::time_point first_byte) {
  if (!stream.wait(POLLIN, ms_until(first_byte))) return {};
  const auto deadline = Clock::now() + kHeadDeadline;
  std::string buffer(kMaxHeadBytes, '\0');
  for (;;) {
    const ssize_t n = ::recv(stream.socket(), buffer.data(), buffer.size(), MSG_PEEK);
    if (n <= 0) return {};
    const std::string_view seen(buffer.data(), size_t(n));
    if (const size_t end = seen.find("\r\n\r\n"); end != std::string_view::npos) {
      return std::string(seen.substr(0, end + 4));
    }
    if (size_t(n) == buffer.size()) return {};
    // More is on its way: wait for it (poll sees only new data once the peeked bytes stay).
    const int left = ms_until(deadline);
    if (left == 0) return {};
    std::this_thread::sleep_for(std::chrono::milliseconds(std::min(left, 5)));
  }
}

void answer(ConnectionStream& stream, int status, const std::string& message) {
  const std::string body = nlohmann::json{{"error", message}}.dump() + "\n";
  const char* reason = status == 400 ? "Bad Request" : status == 403 ? "Forbidden" : "Length Required";
  const std::string response = "HTTP/1.1 " + std::to_string(status) + " " + reason +
                               "\r\nContent-Type: application/json\r\nCache-Control: no-store\r\n"
                               "Connection: close\r\nContent-Length: " +
                               std::to_string(body.size()) + "\r\n\r\n" + body;
  stream.write(response.data(), response.size());
}

}  // namespace

// cpp-httplib's server, each connection first passed through the guard (connection_guard.hpp).
class GuardedServer : public httplib::Server {
 public:
  GuardedServer(const std::string& token) : token_(token) {}
  void set_address(int port, bool any_host) {
    port_ = port;
    any_host_ = any_host;
  }

 private:
  bool process_and_close_socket(socket_t sock) override {
    ConnectionStream stream(sock);
    std::string client;
    int client_port = 0;
    stream.get_remote_ip_and_port(client, client_port);
    bool ok = true;
    for (size_t count = keep_alive_max_count_; count > 0 && is_running(); --count) {
      const auto first_byte =
          Clock::now() +
          std::chrono::seconds(count == keep_alive_max_count_ ? read_timeout_sec_ : keep_alive_timeout_sec_);
      pending_.add(client, sock);
      const std::string head = peek_head(stream, first_byte);
      pending_.remove(client, sock);
      if (head.empty()) break;
      if (const HeadCheck check = check_head(head, token_, port_, any_host_); check.status != 0) {
        answer(stream, check.status, check.message);
        // What the client still sends is read briefly and dropped, so it sees the answer rather
        // than a reset; never more than 64 KiB or 200 ms of it.
        ::shutdown(sock, SHUT_WR);
        char sink[4096];
        const auto until = Clock::now() + std::chrono::milliseconds(200);
        for (size_t drained = 0; drained < 65536 && stream.wait(POLLIN, ms_until(until));) {
          const ssize_t n = ::recv(sock, sink, sizeof sink, 0);
          if (n <= 0) break;
          drained += size_t(n);
        }
        break;
      }
      bool connection_closed = false;
      ok = process_request(stream, count == 1 || !is_running(), connection_closed, nullptr);
      if (!ok || connection_closed) break;
    }
    ::shutdown(sock, SHUT_RDWR);
    ::close(sock);
    return ok;
  }

  const std::string token_;
  int port_ = 0;
  bool any_host_ = false;
  PendingHeads pending_;
};

namespace {

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
                            {"denoised", f.denoised},
                            {"frame_ms", f.frame_ms},
                            {"msamples_per_s", f.msamples_per_s},
                            {"mrays_per_s", f.mrays_per_s},
                            {"mime", f.mime},
                            {"image", base64(f.bytes)}};
  return "event: frame\ndata: " + j.dump() + "\n\n";
}

}  // namespace

bool is_loopback_address(const std::string& host) {
  return host == "localhost" || host == "::1" || host.rfind("127.", 0) == 0;
}

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
    : session_(session), token_(std::move(token)), server_(std::make_unique<GuardedServer>(token_)) {
  server_->new_task_queue = [] { return new httplib::ThreadPool(kServerThreads); };
  server_->set_payload_max_length(kMaxControlBytes);
  server_->set_keep_alive_timeout(1);  // idle connections do not hold a stop back for long
  add_routes();
}

ViewServer::~ViewServer() { stop(); }

int ViewServer::bind(const std::string& host, int port) {
  // SO_REUSEADDR (a restart binds at once) but not cpp-httplib's SO_REUSEPORT, with which a second
  // viewer on the same port also listened and the kernel split connections between the two.
  server_->set_socket_options([](socket_t sock) {
    int yes = 1;
    ::setsockopt(sock, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof yes);
  });
  const int bound = port == 0 ? server_->bind_to_any_port(host) : (server_->bind_to_port(host, port) ? port : -1);
  if (bound <= 0) {
    throw UsageError("--listen/--port: cannot listen on " + host + ":" + std::to_string(port) +
                     " (in use, or not an address of this machine; --port 0 picks a free port)");
  }
  server_->set_address(bound, !is_loopback_address(host));
  return bound;
}

void ViewServer::listen() {
  // listening_ is raised before stopping_ is read and stop() raises stopping_ before it reads
  // listening_ (both sequentially consistent): either this sees the stop, or stop() sees this
  // listen and repeats cpp-httplib's stop until the loop has begun and ended.
  listening_ = true;
  if (!stopping_) server_->listen_after_bind();
  listening_ = false;
}

void ViewServer::stop() {
  stopping_ = true;
  session_.frames().close();
  server_->stop();
  while (listening_) {
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
    server_->stop();
  }
}

void ViewServer::add_routes() {
  httplib::Server& s = *server_;
  s.set_pre_routing_handler([](const httplib::Request&, httplib::Response& res) {
    res.set_header("Cache-Control", "no-store");
    res.set_header("X-Content-Type-Options", "nosniff");
    // The token, Host and Origin were checked on the request head (GuardedServer).
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
    } catch (const nlohmann::json::exception& e) {  // also a number beyond a double (1e400)
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
  const auto image = [this](ImageFile file) {
    const bool exr = file == ImageFile::Exr;
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
  s.Get("/image.png", image(ImageFile::Png));
  s.Get("/image.exr", image(ImageFile::Exr));
}

}  // namespace tracer::view
