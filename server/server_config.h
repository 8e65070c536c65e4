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
  int64_t max_triangles = 2'000'000;
  double max_render_seconds = 600.0;  // wall-clock budget per job; renders stop there, image kept
  double retention_seconds = 24 * 3600.0;
  std::string token;  // empty = no authentication
  bool insecure = false;
  int http_threads = 8;
  double read_timeout_seconds = 10.0;
  double write_timeout_seconds = 30.0;
  int keep_alive_seconds = 5;
  int keep_alive_max_requests = 100;
  double drain_seconds = 1.0;  // after SIGTERM: /readyz answers 503 this long before the port closes
  bool access_log = false;

  // The per-scene caps handed to the scene loader.
  api::Limits scene_limits() const;
  // Threads one job renders with (render_threads resolved against the core count).
  int threads_per_job() const;
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
// True for 127.0.0.0/8, ::1 and "localhost": addresses other machines cannot reach.
bool is_loopback_host(const std::string& host);

const char* serve_usage();

}  // namespace penumbra::server
