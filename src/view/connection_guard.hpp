// What the viewer's server checks of a connection before cpp-httplib reads a request from it:
// the whole request head must arrive within a deadline (a client trickling header lines holds a
// thread for no longer), a client (an address) has at most a few connections still sending their
// head (a further one closes its oldest, so a flood of slow connections cannot lock out a real
// request from the same address), and a head whose token, Host, body framing or method would be
// refused anyway is answered at once, before any body is read.
#pragma once

#include <chrono>
#include <cstdint>
#include <deque>
#include <map>
#include <mutex>
#include <string>
#include <string_view>

namespace tracer::view {

// The deadline for a request head, from its first byte; and how long a kept-alive connection may
// wait for its next request's first byte.
inline constexpr std::chrono::milliseconds kHeadDeadline{2000};
inline constexpr size_t kMaxHeadBytes = 8192;  // cpp-httplib's own limit on a header line
inline constexpr size_t kMaxPendingPerClient = 8;

// Connections still sending their request head, per client address.
class PendingHeads {
 public:
  // Registers `socket` as waiting for its head; if its client already has kMaxPendingPerClient,
  // the oldest of them is shut down (its wait ends at once).
  void add(const std::string& client, int socket);
  void remove(const std::string& client, int socket);

 private:
  std::mutex mutex_;
  std::map<std::string, std::deque<int>> by_client_;
};

// The verdict on a request head (the bytes up to and including the blank line).
struct HeadCheck {
  int status = 0;  // 0: hand it to the server; else answer with this status and close
  std::string message;
};

// Checks a request head as the viewer's routes would: exactly one token equal to `token` in the
// query, a Host naming the listening address (unless `any_host`: --listen was widened), an Origin
// (if sent) of the same host, no Transfer-Encoding (no route reads a chunked body: its size would
// bypass the 4 KiB limit), and a Content-Length on a POST.
HeadCheck check_head(std::string_view head, const std::string& token, int port, bool any_host);

}  // namespace tracer::view
