// GET /v1/jobs/{id}/events: the job's state changes and progress as Server-Sent Events
// (https://html.spec.whatwg.org/multipage/server-sent-events.html). Each event is
//   id: <event id>            increasing (server/jobs/job_events.h)
//   event: <state>            queued, running, succeeded, failed, cancelled
//   data: <the job's JSON>    as GET /v1/jobs/{id} answers it, on one line
// A fresh stream starts with the job as it is now (with the id of its latest change), then one
// event per change, progress at most every 250 ms; it ends after the final state. A reconnect
// with Last-Event-ID: N (or ?last_event_id=N, for clients that cannot set headers) gets the kept
// events after N first. The stream never pins its connection thread for good: it ends when the
// client goes (polled every 250 ms), at shutdown, and after kMaxStream (the client reconnects
// with its last id and misses nothing); a comment line every 15 s keeps proxies from timing out.
#include <httplib.h>
#include <poll.h>
#include <sys/socket.h>

#include <chrono>
#include <memory>

#include "server/http/guarded_server.h"
#include "server/http/job_json.h"
#include "server/http/problem.h"
#include "server/http/request_values.h"
#include "server/http/route_context.h"
#include "server/http/route_table.h"

namespace penumbra::server {
namespace {

using Clock = std::chrono::steady_clock;
constexpr auto kKeepAlive = std::chrono::seconds(15);
constexpr auto kWake = std::chrono::milliseconds(250);
constexpr auto kMaxStream = std::chrono::minutes(30);
// How long EventSource waits before it reconnects (the stream's "retry:" field).
constexpr int kReconnectMs = 2000;

// True when the peer has closed (or reset) the connection. Data it sends (it should send none)
// is left unread.
bool client_gone(int sock) {
  if (sock < 0) return false;
  pollfd p{sock, POLLIN | POLLRDHUP, 0};
  if (::poll(&p, 1, 0) <= 0) return false;
  if (p.revents & (POLLRDHUP | POLLHUP | POLLERR | POLLNVAL)) return true;
  if (p.revents & POLLIN) {
    char c;
    return ::recv(sock, &c, 1, MSG_PEEK | MSG_DONTWAIT) == 0;
  }
  return false;
}

std::string event_text(uint64_t id, const JobView& v) {
  return "id: " + std::to_string(id) + "\nevent: " + to_string(v.record.state) +
         "\ndata: " + job_json(v).dump(-1, ' ', false, nlohmann::ordered_json::error_handler_t::replace) +
         "\n\n";
}

// "" and absent: none; digits: the id; anything else: nullopt (400).
std::optional<uint64_t> parse_event_id(const std::string& text, bool& bad) {
  bad = false;
  if (text.empty()) return std::nullopt;
  uint64_t v = 0;
  for (char c : text) {
    if (c < '0' || c > '9' || v > (UINT64_MAX - 9) / 10) {
      bad = true;
      return std::nullopt;
    }
    v = v * 10 + uint64_t(c - '0');
  }
  return v;
}

struct Stream {
  Stream(JobBackend& jobs, const GuardedServer* server, std::string id)
      : jobs(jobs), server(server), id(std::move(id)) {}
  ~Stream() { jobs.events().close_stream(); }
  Stream(const Stream&) = delete;
  Stream& operator=(const Stream&) = delete;

  JobBackend& jobs;
  const GuardedServer* server;
  std::string id;
  int sock = -1;
  uint64_t last_sent = 0;
  bool resumed = false;
  bool started = false;
  Clock::time_point opened = Clock::now();
  Clock::time_point last_write = Clock::now();
};

bool write(Stream& st, httplib::DataSink& sink, const std::string& text) {
  if (!sink.write(text.data(), text.size())) return false;
  st.last_write = Clock::now();
  return true;
}

bool ending(const Stream& st) {
  return st.jobs.stopping() || (st.server && !st.server->serving()) ||
         Clock::now() - st.opened > kMaxStream;
}

// One call of the content provider: writes what there is within about kWake and returns; the
// library calls again while it returns true and the stream is not done.
bool pump(Stream& st, httplib::DataSink& sink) {
  JobEvents& events = st.jobs.events();
  if (!st.started) {
    st.started = true;
    st.sock = current_connection_socket();
    std::string head = "retry: " + std::to_string(kReconnectMs) + "\n\n";
    const auto v = st.jobs.view(st.id);
    if (!v) {
      sink.done();
      return true;
    }
    // Gives the job a history if it has none (after a restart): its id is above any earlier.
    const uint64_t latest = events.latest_id(v->record, v->queue_position);
    if (!st.resumed) {
      head += event_text(latest, *v);
      st.last_sent = latest;
    }
    if (!write(st, sink, head)) return false;
    if (!st.resumed && is_finished(v->record.state)) {
      sink.done();
      return true;
    }
  }
  const auto deadline = Clock::now() + kWake;
  for (;;) {
    if (client_gone(st.sock)) return false;
    if (ending(st)) {
      sink.done();
      return true;
    }
    const auto v = st.jobs.view(st.id);
    if (!v) {  // deleted or expired meanwhile
      sink.done();
      return true;
    }
    if (v->record.state == JobState::kRunning && v->progress)
      events.sample_progress(v->record, *v->progress);
    std::string text;
    bool final = false;
    for (const JobEvent& e : events.after(st.id, st.last_sent)) {
      text += event_text(e.id, JobView{e.record, e.progress, e.queue_position, false,
                                       st.jobs.frames_in_order()
                                           ? in_order_current_frame(e.record)
                                           : std::nullopt});
      st.last_sent = e.id;
      if (is_finished(e.record.state)) {
        final = true;
        break;
      }
    }
    if (!text.empty()) {
      if (!write(st, sink, text)) return false;
      if (final) sink.done();
      return true;
    }
    // A resumed stream whose client has seen the final state already: nothing more will come.
    if (is_finished(v->record.state)) {
      sink.done();
      return true;
    }
    if (Clock::now() - st.last_write >= kKeepAlive) return write(st, sink, ": keep-alive\n\n");
    if (Clock::now() >= deadline) return true;
    events.wait(st.id, st.last_sent, deadline);
  }
}

void stream_events(const RouteContext& c, const GuardedServer* server, const httplib::Request& req,
                   httplib::Response& res) {
  const std::string id = req.matches[1];
  bool bad = false;
  std::optional<uint64_t> resume;
  if (const auto h = header_value(req, "Last-Event-ID")) {
    resume = parse_event_id(*h, bad);
    if (bad)
      return send_problem(res, req,
                          make_problem(400, "invalid-header", "Invalid header",
                                       "Last-Event-ID must be an event id this server sent "
                                       "(decimal digits)"));
  } else if (const auto q = param_value(req, "last_event_id")) {
    resume = parse_event_id(*q, bad);
    if (bad) return send_problem(res, req, invalid_parameter("last_event_id", "must be an event id (decimal digits)"));
  }
  if (!c.jobs.view(id)) return send_problem(res, req, status_problem(404, "no job " + id));
  if (c.jobs.stopping()) {
    Problem p = status_problem(503, "the server is shutting down; reconnect shortly");
    p.retry_after_seconds = 2;
    return send_problem(res, req, p);
  }
  if (!c.jobs.events().try_open_stream(c.config.max_event_streams)) {
    Problem p = status_problem(503, "too many event streams are open (--max-event-streams " +
                                        std::to_string(c.config.max_event_streams) +
                                        "); retry shortly or poll GET /v1/jobs/{id}");
    p.retry_after_seconds = 5;
    return send_problem(res, req, p);
  }
  // Owned by the provider: the slot is given back when the response (and so the provider) goes,
  // also when the library never calls it (HEAD).
  auto st = std::make_shared<Stream>(c.jobs, server, id);
  st->resumed = resume.has_value();
  st->last_sent = resume.value_or(0);
  res.status = 200;
  res.set_header("Cache-Control", "no-store");
  res.set_header("X-Accel-Buffering", "no");  // nginx: pass events on as they come
  res.set_chunked_content_provider(
      "text/event-stream",
      [st](std::size_t, httplib::DataSink& sink) { return pump(*st, sink); });
}

}  // namespace

void add_event_routes(httplib::Server& s, const RouteContext& c) {
  const auto* server = dynamic_cast<const GuardedServer*>(&s);
  s.Get(kEventsRoute, [&c, server](const httplib::Request& req, httplib::Response& res) {
    stream_events(c, server, req, res);
  });
}

}  // namespace penumbra::server
