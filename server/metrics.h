#pragma once
// Counters, gauges and a histogram exposed at GET /metrics in the Prometheus text format
// (version 0.0.4). Labels are bounded sets (route templates, states, status codes): no per-job
// labels, so the series count stays fixed however many jobs run.
#include <array>
#include <atomic>
#include <cstdint>
#include <map>
#include <mutex>
#include <string>
#include <tuple>

namespace penumbra::server {

class Metrics {
 public:
  static constexpr std::array<double, 12> kRenderSecondsBuckets = {
      0.1, 0.25, 0.5, 1, 2.5, 5, 10, 30, 60, 120, 300, 600};

  void count_request(const std::string& method, const std::string& route, int status);
  void count_submitted() { submitted_.fetch_add(1); }
  void count_rejected(const std::string& reason);
  void observe_render(const std::string& final_state, double seconds, uint64_t rays);
  // A render that ended before its planned samples ("time_limit").
  void count_stopped_early(const std::string& reason);
  // Connections answered by a ConnectionLimits limit ("limit") or refused for want of a
  // connection thread ("overload").
  void count_connection_refused(const std::string& reason);
  // A webhook attempt's outcome: "delivered", "failed_attempt" (retried), "gave_up".
  void count_webhook(const std::string& result);
  // A farm task's scene (server/farm/scene_cache.h): "built" by it, "reused" from an earlier task
  // or another slot of this worker, or "failed".
  void count_scene_preparation(const std::string& outcome);

  struct Gauges {
    std::map<std::string, int64_t> jobs_by_state;
    int64_t queue_depth = 0;
    int64_t queue_capacity = 0;
    int64_t running = 0;
    bool ready = false;
    int64_t webhooks_pending = 0;  // deliveries scheduled or under way
    int64_t event_streams = 0;     // GET /v1/jobs/{id}/events streams open
    std::string extra_text;        // more series in the exposition format (the farm's)
  };
  std::string render_text(const Gauges& gauges) const;

 private:
  mutable std::mutex mutex_;
  std::map<std::tuple<std::string, std::string, int>, uint64_t> requests_;
  std::map<std::string, uint64_t> rejected_;
  std::map<std::string, uint64_t> finished_;
  std::map<std::string, uint64_t> stopped_early_;
  std::map<std::string, uint64_t> connections_refused_;
  std::map<std::string, uint64_t> webhooks_;
  std::map<std::string, uint64_t> scene_preparations_;
  std::array<uint64_t, kRenderSecondsBuckets.size()> render_buckets_{};
  uint64_t render_count_ = 0;
  double render_seconds_sum_ = 0;
  uint64_t rays_total_ = 0;
  double last_mrays_per_second_ = 0;
  std::atomic<uint64_t> submitted_{0};
};

}  // namespace penumbra::server
