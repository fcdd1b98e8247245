// The viewer's HTTP server (cpp-httplib): the page, the state, changes to it, the frames as
// server-sent events, and the current image as PNG or EXR downloads. Every request must carry the
// session's token (?token=...) once, and name this machine as its Host unless --listen widened
// it, so a page from another site cannot drive it; connection_guard.hpp checks each request head
// before cpp-httplib reads the rest.
//
//   GET  /             the page (HTML and script, served from the binary)
//   GET  /state        the view state as JSON
//   POST /control      a JSON object of fields to change (application/json, at most 4 KiB);
//                      the new state, or 400 with {"error": "..."}
//   GET  /events       text/event-stream: "frame" events, each a JSON object of the frame's facts
//                      and its image (base64), always the newest one
//   GET  /image.png    the accumulated image, tone-mapped; /image.exr its radiance
#pragma once

#include <atomic>
#include <memory>
#include <string>

#include "view/view_session.hpp"

namespace httplib {
class Server;
}

namespace tracer::view {

class GuardedServer;

// Frames and at most this many event streams at once (each holds a server thread).
inline constexpr int kMaxEventStreams = 16;
inline constexpr size_t kMaxControlBytes = 4096;

// A token of 128 random bits, as 32 hex digits.
std::string random_token();
// Whether --listen keeps the viewer to this machine (127.0.0.0/8, ::1, localhost).
bool is_loopback_address(const std::string& host);

class ViewServer {
 public:
  ViewServer(ViewSession& session, std::string token);
  ~ViewServer();
  ViewServer(const ViewServer&) = delete;
  ViewServer& operator=(const ViewServer&) = delete;

  // Binds host:port (port 0: any free port); returns the port. Throws UsageError if it cannot.
  int bind(const std::string& host, int port);
  // Serves until stop(); call after bind(). Returns at once if stop() came first.
  void listen();
  // Ends every event stream and the listening; listen() returns. Safe from any thread at any
  // time, before listen() has started too: it waits until a listen in progress has returned.
  void stop();
  const std::string& token() const { return token_; }

 private:
  void add_routes();
  ViewSession& session_;
  const std::string token_;
  std::unique_ptr<GuardedServer> server_;
  std::atomic<int> streams_{0};
  // cpp-httplib's stop() does nothing before its listen loop has begun, so a stop that came
  // between bind() and that moment was lost and listen() blocked in accept for ever.
  std::atomic<bool> stopping_{false};
  std::atomic<bool> listening_{false};
};

}  // namespace tracer::view
