// GET /v1/jobs/{id}/events through the real binary: a stream from queued to succeeded, resuming
// with Last-Event-ID, a client that leaves mid-stream (its thread and slot are given back), the
// stream cap, and shutdown ending open streams.
#include <gtest/gtest.h>

#include "notify_support.h"

namespace penumbra::test {
namespace {

using namespace std::chrono_literals;

TEST(EventStream, FromQueuedToSucceededThenResumeWithLastEventId) {
  TempDir dir;
  ServerProcess server(dir.path(), {"--workers", "1"});
  auto c = server.client();
  const std::string blocker = submit(*c, long_scene());
  wait_for_state(*c, blocker, {"running"});
  const std::string id = submit(*c, tiny_scene(48, 48, 64));
  // The blocker is cancelled once the stream is open, so the job goes queued -> running -> done.
  std::thread cancel([&] {
    std::this_thread::sleep_for(500ms);
    server.client()->Delete(("/v1/jobs/" + blocker).c_str());
  });
  const StreamRead r = read_events(server, id);
  cancel.join();
  ASSERT_EQ(r.status, 200);
  EXPECT_EQ(r.content_type, "text/event-stream");
  EXPECT_EQ(r.text.rfind("retry: ", 0), 0u) << r.text;
  ASSERT_GE(r.events.size(), 3u) << r.text;
  EXPECT_EQ(r.events.front().event, "queued");
  EXPECT_EQ(r.events.front().data["queue_position"], 0);
  EXPECT_EQ(r.events.back().event, "succeeded");
  EXPECT_EQ(r.events.back().data["progress"], 1.0);
  bool saw_running = false;
  for (std::size_t i = 0; i < r.events.size(); ++i) {
    const SseEvent& e = r.events[i];
    EXPECT_EQ(e.event, e.data["state"]) << "event: names the state";
    EXPECT_EQ(e.data["id"], id);
    if (i > 0) EXPECT_GT(e.id, r.events[i - 1].id) << "ids increase";
    saw_running = saw_running || e.event == "running";
  }
  EXPECT_TRUE(saw_running);
  // The final event's data is the job as GET answers it.
  Json got = get_job(*c, id);
  EXPECT_EQ(r.events.back().data["finished_at"], got["finished_at"]);
  EXPECT_EQ(r.events.back().data["stats"], got["stats"]);

  // Resume after the first event: the state changes after it, ending with the final one.
  const StreamRead resumed =
      read_events(server, id, {{"Last-Event-ID", std::to_string(r.events.front().id)}});
  ASSERT_EQ(resumed.status, 200);
  ASSERT_FALSE(resumed.events.empty()) << resumed.text;
  for (const SseEvent& e : resumed.events) EXPECT_GT(e.id, r.events.front().id);
  EXPECT_EQ(resumed.events.front().event, "running");
  EXPECT_EQ(resumed.events.back().event, "succeeded");
  EXPECT_EQ(resumed.events.back().id, r.events.back().id) << "the same event, the same id";
  // Resuming after the final event: nothing more, the stream ends at once.
  const StreamRead after_end =
      read_events(server, id, {{"Last-Event-ID", std::to_string(r.events.back().id)}});
  EXPECT_EQ(after_end.status, 200);
  EXPECT_TRUE(after_end.events.empty()) << after_end.text;
  // The query form for EventSource's first connection.
  const StreamRead by_query = read_events(server, id);
  ASSERT_EQ(by_query.events.size(), 1u) << "a fresh stream of a finished job: its state, then end";
  EXPECT_EQ(by_query.events[0].event, "succeeded");
  auto q = c->Get(("/v1/jobs/" + id + "/events?last_event_id=" +
                   std::to_string(r.events.front().id)).c_str());
  EXPECT_EQ(parse_sse(q->body).back().event, "succeeded");

  EXPECT_EQ(c->Get(("/v1/jobs/" + id + "/events").c_str(), {{"Last-Event-ID", "12x"}})->status,
            400);
  EXPECT_EQ(c->Get("/v1/jobs/0123456789abcdef01234567/events")->status, 404);
}

TEST(EventStream, ResumingAfterARestartGetsTheCurrentState) {
  TempDir dir;
  uint64_t last = 0;
  std::string id;
  {
    ServerProcess server(dir.path());
    auto c = server.client();
    id = submit(*c, tiny_scene());
    const StreamRead r = read_events(server, id);
    ASSERT_FALSE(r.events.empty());
    ASSERT_EQ(r.events.back().event, "succeeded") << r.text;
    last = r.events.back().id;
    // The stream reports a state before the store has committed it: stop gracefully so that
    // the new run finds the job finished (a SIGKILL here would run it again, as kill -9 does).
    server.signal(SIGTERM);
    ASSERT_EQ(server.wait_exit(std::chrono::seconds(20)), 0);
  }
  ServerProcess again(dir.path());
  // An id from the previous run: the new run's ids are above it, the job's state comes again.
  const StreamRead r = read_events(again, id, {{"Last-Event-ID", std::to_string(last - 1)}});
  ASSERT_EQ(r.events.size(), 1u) << r.text;
  EXPECT_EQ(r.events[0].event, "succeeded");
  EXPECT_GT(r.events[0].id, last);
}

// A client that goes away mid-stream: within 3 s its stream has ended (the gauge is back to 0
// and, with --max-event-streams 1, the next stream is let in), no thread is left behind.
TEST(EventStream, ClientLeavingMidStreamFreesItsSlotAndTheCapAnswers503) {
  TempDir dir;
  ServerProcess server(dir.path(), {"--max-event-streams", "1", "--workers", "1"});
  auto c = server.client();
  const std::string blocker = submit(*c, long_scene());
  wait_for_state(*c, blocker, {"running"});
  // A queued job: its stream has nothing to send for 15 s, so only noticing the hang-up ends it.
  const std::string id = submit(*c, tiny_scene());
  for (int round = 0; round < 3; ++round) {
    std::string got;
    auto stream_client = server.client();
    std::atomic<bool> first_event{false};
    std::thread reader([&] {
      stream_client->Get(("/v1/jobs/" + id + "/events").c_str(), [&](const char* d, size_t n) {
        got.append(d, n);
        if (got.find("\n\n", got.find("data: ")) != std::string::npos) first_event = true;
        // Keeps reading until told to leave.
        return !first_event || round < 0;
      });
    });
    reader.join();  // the receiver returned false
    stream_client.reset();  // the client's socket is closed
    EXPECT_TRUE(first_event.load()) << got;
    const auto deadline = std::chrono::steady_clock::now() + 3s;
    while (metric_line(*c, "penumbra_event_streams") != "penumbra_event_streams 0" &&
           std::chrono::steady_clock::now() < deadline)
      std::this_thread::sleep_for(20ms);
    EXPECT_EQ(metric_line(*c, "penumbra_event_streams"), "penumbra_event_streams 0")
        << "round " << round;
  }
  // One stream open: the second is refused with 503 and Retry-After.
  std::atomic<bool> stop{false};
  std::atomic<bool> open{false};
  std::thread holder([&] {
    server.client()->Get(("/v1/jobs/" + id + "/events").c_str(), [&](const char*, size_t) {
      open = true;
      return !stop.load();
    });
  });
  while (!open) std::this_thread::sleep_for(10ms);
  auto refused = c->Get(("/v1/jobs/" + id + "/events").c_str());
  EXPECT_EQ(refused->status, 503);
  EXPECT_TRUE(refused->has_header("Retry-After"));
  stop = true;
  c->Delete(("/v1/jobs/" + blocker).c_str());  // the job runs: events end the holder's stream
  holder.join();
}

TEST(EventStream, ShutdownEndsOpenStreams) {
  TempDir dir;
  ServerProcess server(dir.path(), {"--drain", "0"});
  auto c = server.client();
  const std::string id = submit(*c, long_scene());
  wait_for_state(*c, id, {"running"});
  std::atomic<bool> open{false};
  std::atomic<bool> ended{false};
  std::thread reader([&] {
    server.client()->Get(("/v1/jobs/" + id + "/events").c_str(), [&](const char*, size_t) {
      open = true;
      return true;
    });
    ended = true;
  });
  while (!open) std::this_thread::sleep_for(10ms);
  const auto start = std::chrono::steady_clock::now();
  server.signal(SIGTERM);
  EXPECT_EQ(server.wait_exit(15s), 0);
  reader.join();
  EXPECT_TRUE(ended.load());
  EXPECT_LT(std::chrono::steady_clock::now() - start, 10s);
}

}  // namespace
}  // namespace penumbra::test
