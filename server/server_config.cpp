#include "server/server_config.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <thread>

namespace penumbra::server {
namespace {

std::optional<long long> parse_int(const std::string& s, long long lo, long long hi) {
  if (s.empty()) return std::nullopt;
  char* end = nullptr;
  errno = 0;
  const long long v = std::strtoll(s.c_str(), &end, 10);
  if (errno || *end != '\0' || v < lo || v > hi) return std::nullopt;
  return v;
}

std::optional<double> parse_number(const std::string& s) {
  if (s.empty()) return std::nullopt;
  char* end = nullptr;
  errno = 0;
  const double v = std::strtod(s.c_str(), &end);
  if (errno || *end != '\0' || !std::isfinite(v)) return std::nullopt;
  return v;
}

bool parse_bool(const std::string& s) { return s == "1" || s == "true" || s == "yes" || s == "on"; }

// One setting: its flag, its environment variable, and how a text value is applied.
struct Setting {
  const char* flag;
  const char* env;
  bool takes_value;
  std::function<std::string(ServerConfig&, const std::string&)> apply;  // returns an error or ""
};

std::string bad(const char* flag, const std::string& value, const char* expected) {
  return std::string("invalid value '") + value + "' for " + flag + " (expected " + expected + ")";
}

std::vector<Setting> settings() {
  auto int_setting = [](const char* flag, const char* env, long long lo, long long hi,
                        auto member) {
    return Setting{flag, env, true, [=](ServerConfig& c, const std::string& v) -> std::string {
                     const auto n = parse_int(v, lo, hi);
                     if (!n) return bad(flag, v, ("an integer in [" + std::to_string(lo) + ", " +
                                                  std::to_string(hi) + "]").c_str());
                     c.*member = static_cast<std::remove_reference_t<decltype(c.*member)>>(*n);
                     return "";
                   }};
  };
  auto duration_setting = [](const char* flag, const char* env, double lo, auto member) {
    return Setting{flag, env, true, [=](ServerConfig& c, const std::string& v) -> std::string {
                     const auto d = parse_duration(v);
                     if (!d || *d < lo) return bad(flag, v, "a duration such as 30s, 15m, 24h");
                     c.*member = *d;
                     return "";
                   }};
  };
  auto byte_setting = [](const char* flag, const char* env, auto member) {
    return Setting{flag, env, true, [=](ServerConfig& c, const std::string& v) -> std::string {
                     const auto b = parse_byte_size(v);
                     if (!b || *b == 0) return bad(flag, v, "a size such as 512k, 16M, 1G");
                     c.*member = *b;
                     return "";
                   }};
  };
  auto text_setting = [](const char* flag, const char* env, auto member) {
    return Setting{flag, env, true, [=](ServerConfig& c, const std::string& v) -> std::string {
                     if (v.empty()) return std::string("empty ") + flag;
                     c.*member = v;
                     return "";
                   }};
  };
  return {
      text_setting("--host", "PENUMBRA_HOST", &ServerConfig::host),
      int_setting("--port", "PENUMBRA_PORT", 0, 65535, &ServerConfig::port),
      text_setting("--data-dir", "PENUMBRA_DATA_DIR", &ServerConfig::data_dir),
      int_setting("--workers", "PENUMBRA_WORKERS", 1, 256, &ServerConfig::workers),
      int_setting("--render-threads", "PENUMBRA_RENDER_THREADS", 0, 4096,
                  &ServerConfig::render_threads),
      int_setting("--max-queue", "PENUMBRA_MAX_QUEUE", 0, 1'000'000, &ServerConfig::max_queue),
      {"--max-body", "PENUMBRA_MAX_BODY", true,
       [](ServerConfig& c, const std::string& v) -> std::string {
         const auto b = parse_byte_size(v);
         if (!b || *b == 0) return bad("--max-body", v, "a size such as 16M");
         c.max_body_bytes = *b;
         return "";
       }},
      int_setting("--max-pixels", "PENUMBRA_MAX_PIXELS", 1, int64_t(1) << 40,
                  &ServerConfig::max_pixels),
      int_setting("--max-spp", "PENUMBRA_MAX_SPP", 1, 1 << 20, &ServerConfig::max_spp),
      int_setting("--max-frames", "PENUMBRA_MAX_FRAMES", 1, 100'000, &ServerConfig::max_frames),
      int_setting("--max-triangles", "PENUMBRA_MAX_TRIANGLES", 0, int64_t(1) << 32,
                  &ServerConfig::max_triangles),
      duration_setting("--max-render-time", "PENUMBRA_MAX_RENDER_TIME", 0.001,
                       &ServerConfig::max_render_seconds),
      {"--min-free-space", "PENUMBRA_MIN_FREE_SPACE", true,
       [](ServerConfig& c, const std::string& v) -> std::string {
         const auto b = parse_byte_size(v);
         if (!b) return bad("--min-free-space", v, "a size such as 64M");
         c.min_free_bytes = *b;
         return "";
       }},
      duration_setting("--retention", "PENUMBRA_RETENTION", 0.001, &ServerConfig::retention_seconds),
      {"--token", "PENUMBRA_TOKEN", true,
       [](ServerConfig& c, const std::string& v) -> std::string {
         c.token = v;
         return "";
       }},
      {"--insecure", "PENUMBRA_INSECURE", false,
       [](ServerConfig& c, const std::string& v) -> std::string {
         c.insecure = parse_bool(v);
         return "";
       }},
      int_setting("--http-threads", "PENUMBRA_HTTP_THREADS", 2, 16384, &ServerConfig::http_threads),
      duration_setting("--header-timeout", "PENUMBRA_HEADER_TIMEOUT", 0.001,
                       &ServerConfig::header_timeout_seconds),
      {"--min-transfer-rate", "PENUMBRA_MIN_TRANSFER_RATE", true,
       [](ServerConfig& c, const std::string& v) -> std::string {
         const auto b = parse_byte_size(v);
         if (!b || *b == 0) return bad("--min-transfer-rate", v, "bytes per second such as 8k");
         c.min_transfer_rate = *b;
         return "";
       }},
      int_setting("--max-headers", "PENUMBRA_MAX_HEADERS", 8, 10000, &ServerConfig::max_headers),
      {"--max-header-bytes", "PENUMBRA_MAX_HEADER_BYTES", true,
       [](ServerConfig& c, const std::string& v) -> std::string {
         const auto b = parse_byte_size(v);
         if (!b || *b < 1024 || *b > (64u << 20))
           return bad("--max-header-bytes", v, "a size from 1k to 64M such as 64k");
         c.max_header_bytes = *b;
         return "";
       }},
      duration_setting("--read-timeout", "PENUMBRA_READ_TIMEOUT", 0.001,
                       &ServerConfig::read_timeout_seconds),
      duration_setting("--write-timeout", "PENUMBRA_WRITE_TIMEOUT", 0.001,
                       &ServerConfig::write_timeout_seconds),
      int_setting("--keep-alive", "PENUMBRA_KEEP_ALIVE", 0, 3600, &ServerConfig::keep_alive_seconds),
      int_setting("--keep-alive-requests", "PENUMBRA_KEEP_ALIVE_REQUESTS", 1, 1'000'000,
                  &ServerConfig::keep_alive_max_requests),
      duration_setting("--drain", "PENUMBRA_DRAIN", 0.0, &ServerConfig::drain_seconds),
      byte_setting("--max-asset-size", "PENUMBRA_MAX_ASSET_SIZE", &ServerConfig::max_asset_bytes),
      byte_setting("--max-job-assets", "PENUMBRA_MAX_JOB_ASSETS",
                   &ServerConfig::max_job_asset_bytes),
      byte_setting("--max-asset-store", "PENUMBRA_MAX_ASSET_STORE",
                   &ServerConfig::max_asset_store_bytes),
      int_setting("--max-job-files", "PENUMBRA_MAX_JOB_FILES", 0, 1'000'000,
                  &ServerConfig::max_job_files),
      int_setting("--max-image-pixels", "PENUMBRA_MAX_IMAGE_PIXELS", 1, int64_t(1) << 40,
                  &ServerConfig::max_image_pixels),
      {"--access-log", "PENUMBRA_ACCESS_LOG", false,
       [](ServerConfig& c, const std::string& v) -> std::string {
         c.access_log = parse_bool(v);
         return "";
       }},
      {"--webhook-allow-hosts", "PENUMBRA_WEBHOOK_ALLOW_HOSTS", true,
       [](ServerConfig& c, const std::string& v) -> std::string {
         std::string error;
         if (!parse_allowed_hosts(v, error))
           return bad("--webhook-allow-hosts", v, ("HOST[:PORT],...; " + error).c_str());
         c.webhook_allow_hosts = v;
         return "";
       }},
      duration_setting("--webhook-timeout", "PENUMBRA_WEBHOOK_TIMEOUT", 0.001,
                       &ServerConfig::webhook_timeout_seconds),
      duration_setting("--webhook-retry-for", "PENUMBRA_WEBHOOK_RETRY_FOR", 0.0,
                       &ServerConfig::webhook_retry_seconds),
      int_setting("--max-event-streams", "PENUMBRA_MAX_EVENT_STREAMS", 1, 16384,
                  &ServerConfig::max_event_streams),
      {"--store", "PENUMBRA_STORE", true,
       [](ServerConfig& c, const std::string& v) -> std::string {
         if (v == "sqlite") {
           c.store.clear();
           return "";
         }
         if (v.rfind("postgres://", 0) != 0 && v.rfind("postgresql://", 0) != 0)
           return bad("--store", "(hidden)", "sqlite or a postgres://... URL");
         c.store = v;
         return "";
       }},
      {"--role", "PENUMBRA_ROLE", true,
       [](ServerConfig& c, const std::string& v) -> std::string {
         if (v != "api" && v != "worker" && v != "all") return bad("--role", v, "api, worker or all");
         c.role = v;
         return "";
       }},
      duration_setting("--lease-seconds", "PENUMBRA_LEASE_SECONDS", 1.0,
                       &ServerConfig::lease_seconds),
      duration_setting("--heartbeat", "PENUMBRA_HEARTBEAT", 0.05, &ServerConfig::heartbeat_seconds),
      int_setting("--max-attempts", "PENUMBRA_MAX_ATTEMPTS", 1, 100, &ServerConfig::max_attempts),
      int_setting("--tile-pixels", "PENUMBRA_TILE_PIXELS", 4096, int64_t(1) << 40,
                  &ServerConfig::tile_pixels),
  };
}

}  // namespace

api::Limits ServerConfig::scene_limits() const {
  api::Limits limits;
  limits.max_pixels = max_pixels;
  limits.max_spp = max_spp;
  limits.max_frames = max_frames;
  limits.max_triangles = max_triangles;
  limits.max_time_limit = max_render_seconds;
  limits.max_texture_pixels = max_image_pixels;
  limits.max_mesh_file_bytes = int64_t(max_asset_bytes);
  return limits;
}

int ServerConfig::threads_per_job() const {
  if (render_threads > 0) return render_threads;
  const int cores = int(std::max(1u, std::thread::hardware_concurrency()));
  return std::max(1, cores / std::max(1, workers));
}

std::vector<AllowedHost> ServerConfig::webhook_hosts() const {
  std::string error;
  return parse_allowed_hosts(webhook_allow_hosts, error).value_or(std::vector<AllowedHost>{});
}

std::optional<double> parse_duration(const std::string& text) {
  if (text.empty()) return std::nullopt;
  double unit = 1.0;
  std::string number = text;
  switch (text.back()) {
    case 's': unit = 1; break;
    case 'm': unit = 60; break;
    case 'h': unit = 3600; break;
    case 'd': unit = 86400; break;
    default: unit = 0;
  }
  if (unit != 0) number.pop_back();
  else unit = 1;
  if (text.size() > 2 && text.substr(text.size() - 2) == "ms") {
    number = text.substr(0, text.size() - 2);
    unit = 0.001;
  }
  const auto v = parse_number(number);
  if (!v || *v < 0) return std::nullopt;
  return *v * unit;
}

std::optional<std::size_t> parse_byte_size(const std::string& text) {
  if (text.empty()) return std::nullopt;
  std::size_t unit = 1;
  std::string number = text;
  switch (text.back()) {
    case 'k': case 'K': unit = std::size_t(1) << 10; break;
    case 'M': unit = std::size_t(1) << 20; break;
    case 'G': unit = std::size_t(1) << 30; break;
    default: unit = 0;
  }
  if (unit) number.pop_back();
  else unit = 1;
  const auto v = parse_int(number, 0, (int64_t(1) << 40));
  if (!v) return std::nullopt;
  return std::size_t(*v) * unit;
}


ConfigParse parse_server_config(const std::vector<std::string>& args,
                                const std::function<const char*(const char*)>& getenv) {
  ConfigParse out;
  ServerConfig config;
  const auto all = settings();
  for (const Setting& s : all) {
    if (const char* v = getenv(s.env)) {
      if (std::string err = s.apply(config, v); !err.empty()) {
        out.error = err + " from " + s.env;
        return out;
      }
    }
  }
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& arg = args[i];
    if (arg == "-h" || arg == "--help") {
      out.help = true;
      return out;
    }
    std::string name = arg, value;
    bool has_inline = false;
    if (const auto eq = arg.find('='); arg.rfind("--", 0) == 0 && eq != std::string::npos) {
      name = arg.substr(0, eq);
      value = arg.substr(eq + 1);
      has_inline = true;
    }
    const auto it = std::find_if(all.begin(), all.end(),
                                 [&](const Setting& s) { return name == s.flag; });
    if (it == all.end()) {
      out.error = "unknown option " + arg;
      return out;
    }
    if (it->takes_value && !has_inline) {
      if (i + 1 >= args.size()) {
        out.error = "missing value for " + name;
        return out;
      }
      value = args[++i];
    } else if (!it->takes_value && !has_inline) {
      value = "1";
    }
    if (std::string err = it->apply(config, value); !err.empty()) {
      out.error = err;
      return out;
    }
  }
  if (config.role != "all" && !config.farm()) {
    out.error = "--role " + config.role + " needs a shared store (--store postgres://...)";
    return out;
  }
  if (config.farm() && config.heartbeat_seconds * 2 > config.lease_seconds) {
    out.error = "--heartbeat must be at most half of --lease-seconds, so one late heartbeat "
                "does not lose the lease";
    return out;
  }
  out.config = config;
  return out;
}

const char* serve_usage() {
  return "usage: penumbra serve [options]\n"
         "\n"
         "Runs the HTTP render service (API under /v1, see docs/http-api.md). Every option can also\n"
         "be set by the environment variable in brackets; a flag wins over the variable.\n"
         "\n"
         "  --host ADDR              listen address (default 127.0.0.1) [PENUMBRA_HOST]\n"
         "  --port N                 listen port, 0 = ephemeral (default 8080) [PENUMBRA_PORT]\n"
         "  --data-dir DIR           job database and result images (default ./penumbra-data)\n"
         "                           [PENUMBRA_DATA_DIR]\n"
         "  --workers N              jobs rendered side by side (default 1) [PENUMBRA_WORKERS]\n"
         "  --render-threads N       threads per job, 0 = cores / workers (default 0)\n"
         "                           [PENUMBRA_RENDER_THREADS]\n"
         "  --max-queue N            queued jobs before POST answers 429 (default 64)\n"
         "                           [PENUMBRA_MAX_QUEUE]\n"
         "  --max-body SIZE          request body limit, e.g. 512k, 16M (default 16M) [PENUMBRA_MAX_BODY]\n"
         "  --max-pixels N           width x height limit (default 16777216) [PENUMBRA_MAX_PIXELS]\n"
         "  --max-spp N              samples per pixel limit (default 65536) [PENUMBRA_MAX_SPP]\n"
         "  --max-frames N           frames of one animation job (default 1000) [PENUMBRA_MAX_FRAMES]\n"
         "  --max-triangles N        triangles per scene (default 2000000) [PENUMBRA_MAX_TRIANGLES]\n"
         "  --max-render-time DUR    render time per job; longer renders stop there and keep\n"
         "                           their image (default 10m) [PENUMBRA_MAX_RENDER_TIME]\n"
         "  --min-free-space SIZE    kept free on the data directory's file system beyond the\n"
         "                           worst case of accepted jobs; below it POST is 507 and\n"
         "                           /readyz 503 (default 64M) [PENUMBRA_MIN_FREE_SPACE]\n"
         "  --retention DUR          finished jobs and results are deleted after this\n"
         "                           (default 24h) [PENUMBRA_RETENTION]\n"
         "  --token TOKEN            require 'Authorization: Bearer TOKEN' on every route but\n"
         "                           /healthz (default: none) [PENUMBRA_TOKEN]\n"
         "  --insecure               allow a non-loopback --host without a token [PENUMBRA_INSECURE=1]\n"
         "  --http-threads N         connections served at once, a thread each started on demand;\n"
         "                           more are answered 503 (default 1024) [PENUMBRA_HTTP_THREADS]\n"
         "  --header-timeout DUR     the whole request head must arrive within this (default 10s)\n"
         "                           [PENUMBRA_HEADER_TIMEOUT]\n"
         "  --read-timeout DUR       a body may take this plus its size at the minimum rate\n"
         "                           (default 10s) [PENUMBRA_READ_TIMEOUT]\n"
         "  --write-timeout DUR      a response may take this plus its size at the minimum rate\n"
         "                           (default 30s) [PENUMBRA_WRITE_TIMEOUT]\n"
         "  --min-transfer-rate SIZE bytes per second a body or response averages after its\n"
         "                           grace time (default 8k) [PENUMBRA_MIN_TRANSFER_RATE]\n"
         "  --max-headers N          header lines per request, more -> 431 (default 100)\n"
         "                           [PENUMBRA_MAX_HEADERS]\n"
         "  --max-header-bytes SIZE  request line and headers, more -> 431 (default 64k)\n"
         "                           [PENUMBRA_MAX_HEADER_BYTES]\n"
         "  --keep-alive SECONDS     idle keep-alive connection timeout (default 5)\n"
         "                           [PENUMBRA_KEEP_ALIVE]\n"
         "  --keep-alive-requests N  requests per connection (default 100)\n"
         "                           [PENUMBRA_KEEP_ALIVE_REQUESTS]\n"
         "  --drain DUR              after SIGTERM, /readyz answers 503 this long before the port\n"
         "                           closes (default 1s) [PENUMBRA_DRAIN]\n"
         "  --access-log             one line per request on stderr [PENUMBRA_ACCESS_LOG=1]\n"
         "  --webhook-allow-hosts H  HOST[:PORT],... webhooks may reach; HOST alone = port 80/443\n"
         "                           by scheme (default: none, webhooks off)\n"
         "                           [PENUMBRA_WEBHOOK_ALLOW_HOSTS]\n"
         "  --webhook-timeout DUR    one webhook POST, connect to answer (default 10s)\n"
         "                           [PENUMBRA_WEBHOOK_TIMEOUT]\n"
         "  --webhook-retry-for DUR  a failing delivery is retried (backoff 1s, 2s, 4s ... 5m)\n"
         "                           this long after the job ended (default 1h)\n"
         "                           [PENUMBRA_WEBHOOK_RETRY_FOR]\n"
         "  --max-event-streams N    GET /v1/jobs/{id}/events streams open at once, more -> 503\n"
         "                           (default 256) [PENUMBRA_MAX_EVENT_STREAMS]\n"
         "  --max-asset-size SIZE    one uploaded asset file (PUT /v1/assets, one-shot job\n"
         "                           bodies) (default 256M) [PENUMBRA_MAX_ASSET_SIZE]\n"
         "  --max-job-assets SIZE    all the files one job names (default 1G)\n"
         "                           [PENUMBRA_MAX_JOB_ASSETS]\n"
         "  --max-asset-store SIZE   the whole asset store; the least recently used assets no\n"
         "                           queued or running job needs are evicted (default 10G)\n"
         "                           [PENUMBRA_MAX_ASSET_STORE]\n"
         "  --max-job-files N        files in one job's manifest (default 1000)\n"
         "                           [PENUMBRA_MAX_JOB_FILES]\n"
         "  --max-image-pixels N     width x height of one texture, read from its header\n"
         "                           before decoding (default 67108864) [PENUMBRA_MAX_IMAGE_PIXELS]\n"
         "\n"
         "Render farm (docs/scale-out.md):\n"
         "  --store URL              sqlite (default: jobs.db in --data-dir) or postgres://... :\n"
         "                           jobs and tasks in PostgreSQL, --data-dir the shared volume\n"
         "                           of assets and results [PENUMBRA_STORE]\n"
         "  --role ROLE              api (HTTP only), worker (renders tasks) or all (default)\n"
         "                           [PENUMBRA_ROLE]\n"
         "  --lease-seconds DUR      a claimed task's lease past each heartbeat (default 30s)\n"
         "                           [PENUMBRA_LEASE_SECONDS]\n"
         "  --heartbeat DUR          lease renewal, progress and cancellation check (default 5s;\n"
         "                           at most half the lease) [PENUMBRA_HEARTBEAT]\n"
         "  --max-attempts N         a task failing (or losing its lease) this often fails its\n"
         "                           job with the reason (default 3) [PENUMBRA_MAX_ATTEMPTS]\n"
         "  --tile-pixels N          a frame of more pixels is split into tiles of about N\n"
         "                           pixels, rendered by any workers and merged bit for bit\n"
         "                           (default 65536: a 1024x1024 frame is 16 tiles)\n"
         "                           [PENUMBRA_TILE_PIXELS]\n"
         "\n"
         "Durations: 90, 90s, 15m, 24h, 7d, 250ms.\n";
}

}  // namespace penumbra::server
