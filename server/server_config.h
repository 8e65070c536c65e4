#pragma once
// Everything `penumbra serve` can be told, from flags and environment variables (for containers).
// Each field has its documented default here and in docs/http-api.md.
#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "api/scene_loader.h"
#include "server/jobs/webhook_url.h"

namespace penumbra::server {

struct ServerConfig {
  std::string host = "127.0.0.1";
  int port = 8080;  // 0 picks an ephemeral port (printed on stdout)
  std::string data_dir = "penumbra-data";
  int workers = 1;         // jobs rendered side by side
  int render_threads = 0;  // threads per job; 0 = all cores divided by workers
  int max_queue = 64;      // queued (not yet running) jobs
  std::size_t max_body_bytes = 16u << 20;
  int64_t max_pixels = int64_t(4096) * 4096;
  int max_spp = 65536;
  // Frames of one animation job (422 at /animation/frames beyond): a job is a shot (1000 frames
  // is 42 s at 24 fps); a longer sequence is several jobs, each with its own retry and archive.
  int max_frames = 1000;
  int64_t max_triangles = 2'000'000;
  double max_render_seconds = 600.0;  // wall-clock budget per job; renders stop there, image kept
  double retention_seconds = 24 * 3600.0;
  // Kept free on the data directory's file system beyond every accepted job's worst case:
  // below it POST answers 507 and /readyz is not ready.
  std::size_t min_free_bytes = std::size_t(64) << 20;
  std::string token;  // empty = no authentication
  bool insecure = false;
  // Connections served at once, one thread each, started on demand and gone after 10 s idle;
  // beyond this a connection is answered 503 at once (docs/design-notes.md, slow clients).
  int http_threads = 1024;
  double header_timeout_seconds = 10.0;  // the whole request head, however slowly it comes
  double read_timeout_seconds = 10.0;    // grace for a body before the minimum rate applies
  double write_timeout_seconds = 30.0;   // grace for a response before the minimum rate applies
  std::size_t min_transfer_rate = 8192;  // bytes/s a body or response must average after grace
  int max_headers = 100;                 // header lines per request; more -> 431
  std::size_t max_header_bytes = 65536;  // request line + headers; more -> 431
  int keep_alive_seconds = 5;
  int keep_alive_max_requests = 100;
  double drain_seconds = 1.0;  // after SIGTERM: /readyz answers 503 this long before the port closes
  bool access_log = false;
  // Webhooks (docs/http-api.md, "Notifications"): the hosts they may reach (none = off), how
  // long one POST may take, and how long a delivery is retried before it is given up.
  std::string webhook_allow_hosts;  // "host[:port],..."
  double webhook_timeout_seconds = 10.0;
  double webhook_retry_seconds = 3600.0;
  // GET /v1/jobs/{id}/events streams open at once; each holds a connection thread.
  int max_event_streams = 256;
  // Assets (docs/http-api.md, assets): the content-addressed store and job manifests.
  std::uint64_t max_asset_bytes = std::uint64_t(256) << 20;      // one uploaded file
  std::uint64_t max_job_asset_bytes = std::uint64_t(1) << 30;    // all files of one job
  std::uint64_t max_asset_store_bytes = std::uint64_t(10) << 30;  // the whole store
  int max_job_files = 1000;                                      // manifest entries per job
  int64_t max_image_pixels = int64_t(8192) * 8192;  // one texture, from its header

  // The render farm (docs/scale-out.md). Empty store: one node, SQLite in --data-dir (the
  // default). "postgres://..." or "postgresql://...": the jobs and the task queue live in that
  // PostgreSQL database and --data-dir is the shared volume of assets and results.
  std::string store;
  // What this process does with a PostgreSQL store: "api" answers HTTP only, "worker" renders
  // tasks (its HTTP port answers the same API and the probes), "all" both.
  std::string role = "all";
  double lease_seconds = 30.0;     // a claimed task is the worker's this long past a heartbeat
  double heartbeat_seconds = 5.0;  // lease renewal, progress and the cancellation check
  int max_attempts = 3;            // a task that failed (or lost its lease) this often fails its job
  // A still of more pixels than this is split into windows of about this many pixels, rendered
  // as separate tasks and merged (docs/scale-out.md, "Tiles"): 256x256, so a 1024x1024 frame is
  // 16 tiles, about 4 per worker of a 4-worker farm, which evens out slow and fast regions.
  int64_t tile_pixels = 65536;
  bool farm() const { return !store.empty(); }
  bool renders() const { return role != "api"; }
  // The per-scene caps handed to the scene loader.
  api::Limits scene_limits() const;
  // Threads one job renders with (render_threads resolved against the core count).
  int threads_per_job() const;
  // webhook_allow_hosts parsed (checked when the flags are read, so never malformed here).
  std::vector<AllowedHost> webhook_hosts() const;
};

struct ConfigParse {
  std::optional<ServerConfig> config;
  bool help = false;
  std::string error;  // set when neither config nor help
};

// Flags override environment variables (PENUMBRA_*), which override the defaults.
// `getenv` is injectable so tests need not touch the process environment.
ConfigParse parse_server_config(const std::vector<std::string>& args,
                                const std::function<const char*(const char*)>& getenv);

// "90" / "90s" / "15m" / "24h" / "7d" -> seconds; nullopt when malformed or negative.
std::optional<double> parse_duration(const std::string& text);
// "16777216" / "512k" / "16M" / "1G" (binary units) -> bytes.
std::optional<std::size_t> parse_byte_size(const std::string& text);

const char* serve_usage();

}  // namespace penumbra::server
