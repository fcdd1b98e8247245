#include "view/connection_guard.hpp"

#include <sys/socket.h>

#include <algorithm>
#include <cctype>
#include <vector>

namespace tracer::view {

void PendingHeads::add(const std::string& client, int socket) {
  const std::lock_guard lock(mutex_);
  std::deque<int>& pending = by_client_[client];
  if (pending.size() >= kMaxPendingPerClient) {
    ::shutdown(pending.front(), SHUT_RDWR);  // its owner sees the connection end and closes it
    pending.pop_front();
  }
  pending.push_back(socket);
}

void PendingHeads::remove(const std::string& client, int socket) {
  const std::lock_guard lock(mutex_);
  const auto it = by_client_.find(client);
  if (it == by_client_.end()) return;
  std::deque<int>& pending = it->second;
  pending.erase(std::remove(pending.begin(), pending.end(), socket), pending.end());
  if (pending.empty()) by_client_.erase(it);
}

namespace {

bool same_text(const std::string& given, const std::string& expected) {
  if (given.size() != expected.size()) return false;
  unsigned diff = 0;  // every character compared, so the time says nothing of the token
  for (size_t i = 0; i < expected.size(); ++i) diff |= unsigned(given[i] ^ expected[i]);
  return diff == 0;
}

std::string lower(std::string_view s) {
  std::string out(s);
  for (char& c : out) c = char(std::tolower(static_cast<unsigned char>(c)));
  return out;
}

std::string_view trim_blanks(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r')) s.remove_suffix(1);
  return s;
}

// The values of `name` in a query string, undecoded (a token is hex digits).
std::vector<std::string> query_values(std::string_view query, std::string_view name) {
  std::vector<std::string> values;
  while (!query.empty()) {
    const size_t amp = query.find('&');
    const std::string_view pair = query.substr(0, amp);
    const size_t eq = pair.find('=');
    if (pair.substr(0, eq) == name) values.emplace_back(eq == std::string_view::npos ? "" : pair.substr(eq + 1));
    query = amp == std::string_view::npos ? std::string_view() : query.substr(amp + 1);
  }
  return values;
}

bool is_loopback_host(const std::string& host) {
  return host == "localhost" || host == "[::1]" || host.rfind("127.", 0) == 0;
}

}  // namespace

HeadCheck check_head(std::string_view head, const std::string& token, int port, bool any_host) {
  const size_t line_end = head.find("\r\n");
  const std::string_view request_line = head.substr(0, line_end);
  const size_t sp1 = request_line.find(' '), sp2 = request_line.rfind(' ');
  if (sp1 == std::string_view::npos || sp2 <= sp1) return {400, "bad request"};
  const std::string_view method = request_line.substr(0, sp1), target = request_line.substr(sp1 + 1, sp2 - sp1 - 1);
  const size_t q = target.find('?');
  const std::vector<std::string> tokens =
      query_values(q == std::string_view::npos ? std::string_view() : target.substr(q + 1), "token");
  if (tokens.size() != 1 || !same_text(tokens[0], token)) {
    return {403, "missing or wrong token: open the URL tracer view printed"};
  }
  std::string host, origin, content_length, transfer_encoding;
  for (size_t at = line_end + 2; at < head.size();) {
    const size_t end = head.find("\r\n", at);
    const std::string_view line = head.substr(at, end - at);
    at = end == std::string_view::npos ? head.size() : end + 2;
    const size_t colon = line.find(':');
    if (colon == std::string_view::npos) continue;
    const std::string name = lower(line.substr(0, colon));
    const std::string value(trim_blanks(line.substr(colon + 1)));
    if (name == "host") host = lower(value);
    if (name == "origin") origin = lower(value);
    if (name == "content-length") content_length = value;
    if (name == "transfer-encoding") transfer_encoding = value;
  }
  // A page of another site that resolves its own name to this machine (DNS rebinding) sends its
  // own name as Host: only this machine's loopback names are served, unless --listen widened it.
  const std::string suffix = ":" + std::to_string(port);
  if (!any_host) {
    const bool ours = host.size() > suffix.size() &&
                      host.compare(host.size() - suffix.size(), suffix.size(), suffix) == 0 &&
                      is_loopback_host(host.substr(0, host.size() - suffix.size()));
    if (!ours) return {403, "Host '" + host.substr(0, host.rfind(':')) + "' is not this viewer's address"};
  }
  if (!origin.empty() && origin != "http://" + host) return {403, "Origin '" + origin + "' is not this viewer's page"};
  if (!transfer_encoding.empty()) return {400, "Transfer-Encoding is not accepted: send a Content-Length"};
  if (method == "POST" && content_length.empty()) return {411, "a POST needs a Content-Length"};
  return {};
}

}  // namespace tracer::view
