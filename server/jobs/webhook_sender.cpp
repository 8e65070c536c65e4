#include "server/jobs/webhook_sender.h"

#include <httplib.h>
#include <netdb.h>
#include <sys/socket.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>

#include "api/version.h"
#include "server/jobs/unix_time.h"
#include "server/jobs/webhook_signature.h"

namespace penumbra::server {
namespace {

constexpr double kFirstDelaySeconds = 1.0;
constexpr double kMaxDelaySeconds = 300.0;

// The first address the host resolves to, numeric; "" and an error when it resolves to none.
std::string resolve(const std::string& host, std::string& error) {
  addrinfo hints{};
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_STREAM;
  addrinfo* found = nullptr;
  const int rc = ::getaddrinfo(host.c_str(), nullptr, &hints, &found);
  if (rc != 0 || !found) {
    error = "cannot resolve host '" + host + "': " + gai_strerror(rc);
    return "";
  }
  char text[NI_MAXHOST] = {0};
  const int ni = ::getnameinfo(found->ai_addr, found->ai_addrlen, text, sizeof text, nullptr, 0,
                               NI_NUMERICHOST);
  ::freeaddrinfo(found);
  if (ni != 0) {
    error = "cannot resolve host '" + host + "'";
    return "";
  }
  return text;
}

// What failed, in words (cpp-httplib's own names are terse: "Connection", "Read").
std::string describe(httplib::Error e) {
  switch (e) {
    case httplib::Error::Connection: return "could not connect";
    case httplib::Error::ConnectionTimeout: return "connecting timed out";
    case httplib::Error::Read: return "no answer in time (or the connection was reset)";
    case httplib::Error::Write: return "the request could not be sent";
    case httplib::Error::SSLConnection: return "TLS handshake failed";
    case httplib::Error::SSLLoadingCerts: return "the system's CA certificates could not be loaded";
    case httplib::Error::SSLServerVerification:
      return "the server's TLS certificate did not verify";
    default: return httplib::to_string(e);
  }
}

double uniform01() {
  static thread_local std::mt19937_64 rng{std::random_device{}()};
  return std::uniform_real_distribution<double>(0.0, 1.0)(rng);
}

}  // namespace

double webhook_backoff_seconds(int attempts, double unit_random) {
  const double cap =
      std::min(kMaxDelaySeconds, kFirstDelaySeconds * std::pow(2.0, std::max(0, attempts - 1)));
  return cap / 2 + cap / 2 * std::clamp(unit_random, 0.0, 1.0);
}

WebhookSender::WebhookSender(WebhookSettings settings, Metrics& metrics)
    : settings_(std::move(settings)), metrics_(metrics) {}

WebhookSender::~WebhookSender() { stop(); }

bool WebhookSender::pending(const JobRecord& r) {
  return !r.notify.url.empty() && is_finished(r.state) && r.notify.delivered_at == 0 &&
         r.notify.gave_up_at == 0;
}

void WebhookSender::start(Hooks hooks) {
  hooks_ = std::move(hooks);
  for (int i = 0; i < std::max(1, settings_.threads); ++i)
    threads_.emplace_back([this] { loop(); });
}

void WebhookSender::schedule(const std::string& id, double due_unix) {
  {
    std::lock_guard lock(mutex_);
    if (stopping_ || in_flight_ids_.count(id)) return;  // the attempt under way reschedules
    const auto [it, inserted] = due_.emplace(id, due_unix);
    if (!inserted) it->second = std::min(it->second, due_unix);
  }
  cv_.notify_one();
}

std::size_t WebhookSender::backlog() const {
  std::lock_guard lock(mutex_);
  return due_.size() + in_flight_;
}

void WebhookSender::stop() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  cv_.notify_all();
  for (auto& t : threads_)
    if (t.joinable()) t.join();
  threads_.clear();
}

void WebhookSender::loop() {
  std::unique_lock lock(mutex_);
  while (!stopping_) {
    if (due_.empty()) {
      cv_.wait(lock);
      continue;
    }
    const auto next = std::min_element(due_.begin(), due_.end(), [](const auto& a, const auto& b) {
      return a.second < b.second;
    });
    const double wait = next->second - unix_now();
    if (wait > 0) {
      // Woken early by a new schedule() or stop(); the 1 s bound follows clock changes.
      cv_.wait_for(lock, std::chrono::duration<double>(std::min(wait, 1.0)));
      continue;
    }
    const std::string id = next->first;
    due_.erase(next);
    ++in_flight_;
    in_flight_ids_.insert(id);
    lock.unlock();
    try {
      deliver(id);
    } catch (const std::exception& e) {
      std::fprintf(stderr, "penumbra serve: webhook of job %s: internal error: %s\n", id.c_str(),
                   e.what());
    }
    lock.lock();
    --in_flight_;
    in_flight_ids_.erase(id);
    if (const auto again = reschedule_.find(id); again != reschedule_.end()) {
      due_.emplace(id, again->second);
      reschedule_.erase(again);
    }
  }
}

void WebhookSender::deliver(const std::string& id) {
  const auto record = hooks_.find(id);
  if (!record || !pending(*record)) return;  // deleted, delivered or given up meanwhile
  JobRecord::Notify n = record->notify;
  const double now = unix_now();
  std::string error;
  int status = 0;
  const ParsedWebhookUrl parsed = parse_webhook_url(n.url);
  bool permanent = false;
  if (!parsed.url) {
    error = "the URL " + parsed.error;
    permanent = true;
  } else if (!host_allowed(*parsed.url, settings_.allowed)) {
    // The operator no longer allows this host (a restart with other --webhook-allow-hosts).
    error = "host '" + parsed.url->host + "' port " + std::to_string(parsed.url->port) +
            " is no longer among the hosts webhooks may reach";
    permanent = true;
  } else {
    const WebhookUrl& url = *parsed.url;
    const std::string address = resolve(url.host, error);
    if (!address.empty()) {
      const std::string body = hooks_.body(*record);
      httplib::Client client(url.origin());
      // Connect to the address checked above, whatever a second lookup would answer; for https
      // the certificate is still verified against the host name (SNI and hostname check).
      if (address != url.host) client.set_hostname_addr_map({{url.host, address}});
      const auto timeout = std::chrono::duration<double>(settings_.timeout_seconds);
      client.set_connection_timeout(timeout);
      client.set_read_timeout(timeout);
      client.set_write_timeout(timeout);
      client.set_follow_location(false);
      client.set_keep_alive(false);
      if (url.https) client.enable_server_certificate_verification(true);
      httplib::Request req;
      req.method = "POST";
      req.path = url.target;
      req.body = body;
      req.set_header("Content-Type", "application/json");
      req.set_header("User-Agent", std::string("penumbra/") + api::kVersion);
      req.set_header("X-Penumbra-Event", std::string("job.") + to_string(record->state));
      req.set_header("X-Penumbra-Delivery", id + "-" + to_string(record->state));
      req.set_header("X-Penumbra-Attempt", std::to_string(n.attempts + 1));
      req.set_header("X-Penumbra-Signature", webhook_signature(n.secret, body));
      std::size_t received = 0;
      req.content_receiver = [&received](const char*, size_t length, uint64_t, uint64_t) {
        received += length;
        return received <= kMaxAnswerBytes;  // the answer's body is not needed
      };
      httplib::Response res;
      httplib::Error result = httplib::Error::Success;
      const bool ok = client.send(req, res, result);
      status = res.status > 0 ? res.status : 0;
      if (status >= 200 && status < 300) {
        // A 2xx whose body we stopped reading is still a delivery.
      } else if (status > 0) {
        error = "HTTP " + std::to_string(status) +
                (status >= 300 && status < 400 ? " (redirects are not followed)" : "");
      } else {
        error = describe(ok ? httplib::Error::Unknown : result);
      }
    }
  }
  ++n.attempts;
  n.last_attempt_at = now;
  n.last_status = status;
  n.last_error = error;
  n.next_attempt_at = 0;
  if (error.empty()) {
    n.delivered_at = unix_now();
    metrics_.count_webhook("delivered");
  } else {
    const double delay = webhook_backoff_seconds(n.attempts, uniform01());
    const double next = unix_now() + delay;
    if (permanent || next > record->finished_at + settings_.retry_seconds) {
      n.gave_up_at = unix_now();
      metrics_.count_webhook("gave_up");
      std::fprintf(stderr, "penumbra serve: webhook of job %s given up after %d attempt(s): %s\n",
                   id.c_str(), n.attempts, error.c_str());
    } else {
      n.next_attempt_at = next;
      metrics_.count_webhook("failed_attempt");
    }
  }
  hooks_.save(id, n);
  if (n.next_attempt_at > 0) {
    std::lock_guard lock(mutex_);
    reschedule_[id] = n.next_attempt_at;  // taken up by loop() once this attempt is done
  }
}

}  // namespace penumbra::server
