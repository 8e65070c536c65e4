#include "server/metrics.h"

#include <sstream>

namespace penumbra::server {

void Metrics::count_request(const std::string& method, const std::string& route, int status) {
  std::lock_guard lock(mutex_);
  ++requests_[{method, route, status}];
}

void Metrics::count_rejected(const std::string& reason) {
  std::lock_guard lock(mutex_);
  ++rejected_[reason];
}

void Metrics::count_stopped_early(const std::string& reason) {
  std::lock_guard lock(mutex_);
  ++stopped_early_[reason];
}

void Metrics::count_connection_refused(const std::string& reason) {
  std::lock_guard lock(mutex_);
  ++connections_refused_[reason];
}

void Metrics::count_webhook(const std::string& result) {
  std::lock_guard lock(mutex_);
  ++webhooks_[result];
}

void Metrics::count_scene_preparation(const std::string& outcome) {
  std::lock_guard lock(mutex_);
  ++scene_preparations_[outcome];
}

void Metrics::observe_render(const std::string& final_state, double seconds, uint64_t rays) {
  std::lock_guard lock(mutex_);
  ++finished_[final_state];
  if (seconds <= 0) return;  // never rendered (cancelled while queued, failed validation)
  for (std::size_t i = 0; i < kRenderSecondsBuckets.size(); ++i)
    if (seconds <= kRenderSecondsBuckets[i]) ++render_buckets_[i];
  ++render_count_;
  render_seconds_sum_ += seconds;
  rays_total_ += rays;
  if (seconds > 0) last_mrays_per_second_ = double(rays) / seconds * 1e-6;
}

std::string Metrics::render_text(const Gauges& g) const {
  std::ostringstream o;
  o.precision(10);
  std::lock_guard lock(mutex_);
  o << "# HELP penumbra_up Whether the service accepts new jobs (1) or is shutting down (0).\n"
       "# TYPE penumbra_up gauge\npenumbra_up "
    << (g.ready ? 1 : 0) << "\n";
  o << "# HELP penumbra_jobs Jobs in the store by state.\n# TYPE penumbra_jobs gauge\n";
  for (const char* state : {"queued", "running", "succeeded", "failed", "cancelled"}) {
    const auto it = g.jobs_by_state.find(state);
    o << "penumbra_jobs{state=\"" << state << "\"} " << (it == g.jobs_by_state.end() ? 0 : it->second)
      << "\n";
  }
  o << "# HELP penumbra_queue_depth Jobs waiting for a worker.\n# TYPE penumbra_queue_depth gauge\n"
    << "penumbra_queue_depth " << g.queue_depth << "\n";
  o << "# HELP penumbra_queue_capacity Jobs the queue holds before POST answers 429.\n"
       "# TYPE penumbra_queue_capacity gauge\npenumbra_queue_capacity "
    << g.queue_capacity << "\n";
  o << "# HELP penumbra_jobs_running Jobs rendering now.\n# TYPE penumbra_jobs_running gauge\n"
    << "penumbra_jobs_running " << g.running << "\n";
  o << "# HELP penumbra_jobs_submitted_total Jobs accepted (202) since start.\n"
       "# TYPE penumbra_jobs_submitted_total counter\npenumbra_jobs_submitted_total "
    << submitted_.load() << "\n";
  o << "# HELP penumbra_jobs_rejected_total Submissions refused, by reason.\n"
       "# TYPE penumbra_jobs_rejected_total counter\n";
  for (const auto& [reason, n] : rejected_)
    o << "penumbra_jobs_rejected_total{reason=\"" << reason << "\"} " << n << "\n";
  o << "# HELP penumbra_jobs_finished_total Renders that ended, by final state.\n"
       "# TYPE penumbra_jobs_finished_total counter\n";
  for (const auto& [state, n] : finished_)
    o << "penumbra_jobs_finished_total{state=\"" << state << "\"} " << n << "\n";
  o << "# HELP penumbra_jobs_stopped_early_total Renders that ended before their planned "
       "samples, by reason.\n# TYPE penumbra_jobs_stopped_early_total counter\n"
    << "penumbra_jobs_stopped_early_total{reason=\"time_limit\"} "
    << (stopped_early_.count("time_limit") ? stopped_early_.at("time_limit") : 0) << "\n";
  o << "# HELP penumbra_http_connections_refused_total Connections answered by a head or rate "
       "limit (limit) or refused for want of a connection thread (overload).\n"
       "# TYPE penumbra_http_connections_refused_total counter\n";
  for (const char* reason : {"limit", "overload"})
    o << "penumbra_http_connections_refused_total{reason=\"" << reason << "\"} "
      << (connections_refused_.count(reason) ? connections_refused_.at(reason) : 0) << "\n";
  o << "# HELP penumbra_webhook_attempts_total Webhook POSTs by outcome: delivered (2xx), "
       "failed_attempt (retried later), gave_up (retries exhausted or host no longer allowed).\n"
       "# TYPE penumbra_webhook_attempts_total counter\n";
  for (const char* result : {"delivered", "failed_attempt", "gave_up"})
    o << "penumbra_webhook_attempts_total{result=\"" << result << "\"} "
      << (webhooks_.count(result) ? webhooks_.at(result) : 0) << "\n";
  o << "# HELP penumbra_farm_scene_preparations_total The scenes of a farm worker's tile and frame "
       "tasks: built by the task, reused from an earlier task or another slot of the worker, "
       "failed.\n"
       "# TYPE penumbra_farm_scene_preparations_total counter\n";
  for (const char* outcome : {"built", "reused", "failed"})
    o << "penumbra_farm_scene_preparations_total{outcome=\"" << outcome << "\"} "
      << (scene_preparations_.count(outcome) ? scene_preparations_.at(outcome) : 0) << "\n";
  o << "# HELP penumbra_webhooks_pending Webhook deliveries scheduled or under way.\n"
       "# TYPE penumbra_webhooks_pending gauge\npenumbra_webhooks_pending "
    << g.webhooks_pending << "\n";
  o << "# HELP penumbra_event_streams Server-Sent Events streams open.\n"
       "# TYPE penumbra_event_streams gauge\npenumbra_event_streams "
    << g.event_streams << "\n";
  o << "# HELP penumbra_render_seconds Wall-clock time of a render (scene build excluded).\n"
       "# TYPE penumbra_render_seconds histogram\n";
  for (std::size_t i = 0; i < kRenderSecondsBuckets.size(); ++i)
    o << "penumbra_render_seconds_bucket{le=\"" << kRenderSecondsBuckets[i] << "\"} "
      << render_buckets_[i] << "\n";
  o << "penumbra_render_seconds_bucket{le=\"+Inf\"} " << render_count_ << "\n"
    << "penumbra_render_seconds_sum " << render_seconds_sum_ << "\n"
    << "penumbra_render_seconds_count " << render_count_ << "\n";
  o << "# HELP penumbra_rays_total Rays traced by finished renders.\n"
       "# TYPE penumbra_rays_total counter\npenumbra_rays_total "
    << rays_total_ << "\n";
  o << "# HELP penumbra_render_mrays_per_second Millions of rays per second of the last render.\n"
       "# TYPE penumbra_render_mrays_per_second gauge\npenumbra_render_mrays_per_second "
    << last_mrays_per_second_ << "\n";
  o << "# HELP penumbra_http_requests_total HTTP requests by method, route template and status.\n"
       "# TYPE penumbra_http_requests_total counter\n";
  for (const auto& [key, n] : requests_) {
    const auto& [method, route, status] = key;
    o << "penumbra_http_requests_total{method=\"" << method << "\",route=\"" << route
      << "\",status=\"" << status << "\"} " << n << "\n";
  }
  o << g.extra_text;
  return o.str();
}

}  // namespace penumbra::server
