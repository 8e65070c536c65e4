#pragma once
// Test helpers for the notification tests (header-only): a Server-Sent Events parser, a stream
// reader over the real HTTP connection, and a webhook receiver on loopback.
#include <atomic>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "server_process.h"

namespace penumbra::test {

struct SseEvent {
  uint64_t id = 0;
  std::string event;
  Json data;
};

// Splits the text of an event stream into events (comments and retry lines skipped).
inline std::vector<SseEvent> parse_sse(const std::string& text) {
  std::vector<SseEvent> out;
  std::size_t at = 0;
  while (at < text.size()) {
    auto end = text.find("\n\n", at);
    if (end == std::string::npos) break;
    const std::string block = text.substr(at, end - at);
    at = end + 2;
    SseEvent e;
    bool has_data = false;
    std::size_t line_at = 0;
    while (line_at <= block.size()) {
      auto nl = block.find('\n', line_at);
      const std::string line = block.substr(line_at, nl == std::string::npos ? std::string::npos : nl - line_at);
      if (line.rfind("id: ", 0) == 0) e.id = std::stoull(line.substr(4));
      if (line.rfind("event: ", 0) == 0) e.event = line.substr(7);
      if (line.rfind("data: ", 0) == 0) {
        e.data = Json::parse(line.substr(6));
        has_data = true;
      }
      if (nl == std::string::npos) break;
      line_at = nl + 1;
    }
    if (has_data) out.push_back(std::move(e));
  }
  return out;
}

// GET /v1/jobs/{id}/events read to its end (the server closes it after the final state).
struct StreamRead {
  int status = 0;
  std::string content_type;
  std::string text;
  std::vector<SseEvent> events;
};
inline StreamRead read_events(const ServerProcess& server, const std::string& id,
                              const httplib::Headers& headers = {}) {
  auto c = server.client();
  c->set_read_timeout(60);
  StreamRead r;
  auto res = c->Get(
      ("/v1/jobs/" + id + "/events").c_str(), headers,
      [&](const httplib::Response& response) {
        r.status = response.status;
        r.content_type = response.get_header_value("Content-Type");
        return true;
      },
      [&](const char* data, size_t length) {
        r.text.append(data, length);
        return true;
      });
  if (res && r.status == 0) r.status = res->status;
  if (res && r.text.empty()) r.text = res->body;
  r.events = parse_sse(r.text);
  return r;
}

inline std::string metric_line(httplib::Client& c, const std::string& name) {
  const std::string text = c.Get("/metrics")->body;
  const auto at = text.find("\n" + name + " ");
  if (at == std::string::npos) return "";
  return text.substr(at + 1, text.find('\n', at + 1) - at - 1);
}

// An HTTP server on 127.0.0.1 (ephemeral port) that records the POSTs it gets and answers the
// first `failures` of them 503, the others 200.
class WebhookReceiver {
 public:
  struct Hit {
    std::string body, signature, delivery, event, attempt, content_type;
  };
  explicit WebhookReceiver(int failures, int port = 0) : failures_(failures) {
    server_.Post("/hook", [this](const httplib::Request& req, httplib::Response& res) {
      std::lock_guard lock(mutex_);
      hits_.push_back({req.body, req.get_header_value("X-Penumbra-Signature"),
                       req.get_header_value("X-Penumbra-Delivery"),
                       req.get_header_value("X-Penumbra-Event"),
                       req.get_header_value("X-Penumbra-Attempt"),
                       req.get_header_value("Content-Type")});
      res.status = int(hits_.size()) <= failures_ ? 503 : 200;
      res.set_content(res.status == 200 ? "ok" : "try later", "text/plain");
    });
    port_ = port ? (server_.bind_to_port("127.0.0.1", port) ? port : -1)
                 : server_.bind_to_any_port("127.0.0.1");
    if (port_ <= 0) throw std::runtime_error("receiver: cannot bind");
    thread_ = std::thread([this] { server_.listen_after_bind(); });
    while (!server_.is_running()) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  ~WebhookReceiver() {
    server_.stop();
    thread_.join();
  }
  int port() const { return port_; }
  std::string url() const { return "http://127.0.0.1:" + std::to_string(port_) + "/hook"; }
  std::vector<Hit> hits() const {
    std::lock_guard lock(mutex_);
    return hits_;
  }
  void set_failures(int n) {
    std::lock_guard lock(mutex_);
    failures_ = int(hits_.size()) + n;
  }
  // Waits until at least n POSTs came; returns them.
  std::vector<Hit> wait_for(std::size_t n, std::chrono::seconds timeout) const {
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    while (hits().size() < n && std::chrono::steady_clock::now() < deadline)
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    return hits();
  }

 private:
  httplib::Server server_;
  int failures_;
  int port_ = 0;
  std::thread thread_;
  mutable std::mutex mutex_;
  std::vector<Hit> hits_;
};

}  // namespace penumbra::test
