#include "server/http/connection_stream.h"

#include <netdb.h>
#include <poll.h>
#include <sys/select.h>
#include <sys/socket.h>

#include <algorithm>
#include <cerrno>
#include <cstring>

#include "server/http/header_line_check.h"
#include "server/text_util.h"

namespace penumbra::server {
namespace {

constexpr std::size_t kBufferSize = 16384;

// Milliseconds from now to deadline for poll(), at least 0.
int ms_until(ConnectionStream::Clock::time_point deadline) {
  const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
      deadline - ConnectionStream::Clock::now());
  return int(std::clamp<long long>(left.count(), 0, 1'000'000));
}

void numeric_name(const sockaddr_storage& addr, socklen_t len, std::string& ip, int& port) {
  char host[NI_MAXHOST];
  char serv[NI_MAXSERV];
  if (::getnameinfo(reinterpret_cast<const sockaddr*>(&addr), len, host, sizeof host, serv,
                    sizeof serv, NI_NUMERICHOST | NI_NUMERICSERV) == 0) {
    ip = host;
    port = std::atoi(serv);
  }
}

}  // namespace

ConnectionStream::ConnectionStream(int sock, const ConnectionLimits& limits)
    : sock_(sock), limits_(limits), buffer_(kBufferSize) {
  begin_request();
}

void ConnectionStream::begin_request() {
  phase_ = Phase::kHead;
  head_deadline_ = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                      std::chrono::duration<double>(limits_.header_seconds));
  line_.clear();
  line_index_ = 0;
  head_bytes_ = 0;
  body_bytes_ = 0;
  content_length_ = 0;
  written_ = 0;
}

ConnectionStream::Clock::time_point ConnectionStream::rate_deadline(Clock::time_point start,
                                                                    double grace,
                                                                    std::size_t bytes) const {
  const double seconds = grace + double(bytes) / std::max(1.0, limits_.min_bytes_per_second);
  return start +
         std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(seconds));
}

bool ConnectionStream::wait_for_request(std::chrono::milliseconds timeout,
                                        const std::function<bool()>& keep_going) {
  if (buffer_begin_ < buffer_end_) return true;
  const auto deadline = Clock::now() + timeout;
  while (keep_going()) {
    pollfd p{sock_, POLLIN, 0};
    const int wait = std::min(100, ms_until(deadline));
    const int r = ::poll(&p, 1, wait);
    if (r > 0) return true;
    if (r < 0 && errno != EINTR) return false;
    if (Clock::now() >= deadline) return false;
  }
  return false;
}

ssize_t ConnectionStream::fill(Clock::time_point deadline) {
  buffer_begin_ = buffer_end_ = 0;
  for (;;) {
    const ssize_t n = ::recv(sock_, buffer_.data(), buffer_.size(), MSG_DONTWAIT);
    if (n >= 0) {
      buffer_end_ = std::size_t(n);
      return n;
    }
    if (errno == EINTR) continue;
    if (errno != EAGAIN && errno != EWOULDBLOCK) return -1;
    pollfd p{sock_, POLLIN, 0};
    const int r = ::poll(&p, 1, ms_until(deadline));
    if (r == 0) {
      timed_out_ = true;
      return -1;
    }
    if (r < 0 && errno != EINTR) return -1;
  }
}

void ConnectionStream::reject(Problem p) {
  if (!rejection_) rejection_ = std::move(p);
}

bool ConnectionStream::on_head_byte(char c) {
  if (++head_bytes_ > limits_.max_header_bytes) {
    Problem p = make_problem(
        431, "headers-too-large", "Request Header Fields Too Large",
        "the request head exceeds " + std::to_string(limits_.max_header_bytes) + " bytes");
    p.extensions["limit"] = limits_.max_header_bytes;
    reject(std::move(p));
    return false;
  }
  if (c != '\n') {
    line_ += c;
    // Lengths count the CR LF, as the library's own limits do: with the LF still to come,
    // line_ (content and CR) may hold one byte less than the limit.
    if (line_index_ == 0 && line_.size() + 1 > limits_.max_request_line) {
      reject(make_problem(
          414, "uri-too-long", "URI Too Long",
          "the request line exceeds " + std::to_string(limits_.max_request_line) + " bytes"));
      return false;
    }
    if (line_index_ > 0 && line_.size() + 1 > limits_.max_header_line) {
      Problem p = make_problem(
          431, "headers-too-large", "Request Header Fields Too Large",
          "a header line exceeds " + std::to_string(limits_.max_header_line) + " bytes");
      p.extensions["limit"] = limits_.max_header_line;
      reject(std::move(p));
      return false;
    }
    return true;
  }
  // The library takes only CR LF as a line end and skips other lines unseen: a bare LF would make
  // the two of us disagree on where the head ends, so it is refused (RFC 9112 section 2.2 allows).
  if (line_.empty() || line_.back() != '\r') {
    reject(make_problem(400, "bad-header", "Bad Request", "head lines must end with CR LF"));
    return false;
  }
  line_.pop_back();
  if (line_.empty() && line_index_ > 0) {
    phase_ = Phase::kBody;
    body_start_ = Clock::now();
    body_bytes_ = 0;
    return true;
  }
  if (line_index_ > limits_.max_header_count) {
    Problem p = make_problem(
        431, "too-many-headers", "Request Header Fields Too Large",
        "the request has more than " + std::to_string(limits_.max_header_count) + " header lines");
    p.extensions["limit"] = limits_.max_header_count;
    reject(std::move(p));
    return false;
  }
  if (auto p = check_head_line(line_, line_index_, limits_)) {
    reject(std::move(*p));
    return false;
  }
  if (line_index_ > 0 && line_.size() > 15 &&
      ascii_lower(line_.substr(0, 15)) == "content-length:") {
    // Only to know whether the body was read; request_guard refuses lengths that are not
    // plain numbers.
    const std::string_view v = trim_ows(std::string_view(line_).substr(15));
    std::size_t n = 0;
    bool digits = !v.empty() && v.size() <= 18;
    for (char ch : v) {
      if (ch < '0' || ch > '9') digits = false;
      n = n * 10 + std::size_t(ch - '0');
    }
    if (digits) content_length_ = n;
  }
  ++line_index_;
  line_.clear();
  return true;
}

ssize_t ConnectionStream::read(char* ptr, size_t size) {
  if (rejection_ || broken_) return -1;
  if (phase_ == Phase::kResponse) begin_request();  // a pipelined request
  if (buffer_begin_ == buffer_end_) {
    const auto deadline = phase_ == Phase::kHead
                              ? head_deadline_
                              : rate_deadline(body_start_, limits_.body_grace_seconds, body_bytes_);
    const ssize_t n = fill(deadline);
    if (n == 0) return 0;
    if (n < 0) {
      if (timed_out_) {
        reject(phase_ == Phase::kHead
                   ? make_problem(408, "request-timeout", "Request Timeout",
                                  "the request head did not arrive within the time allowed")
                   : make_problem(408, "request-timeout", "Request Timeout",
                                  "the request body arrived slower than the minimum rate"));
      } else {
        broken_ = true;
      }
      return -1;
    }
  }
  std::size_t n = 0;
  if (phase_ == Phase::kHead) {
    while (n < size && buffer_begin_ < buffer_end_ && phase_ == Phase::kHead) {
      const char c = buffer_[buffer_begin_++];
      ptr[n++] = c;
      if (!on_head_byte(c)) return -1;
    }
    return ssize_t(n);
  }
  n = std::min(size, buffer_end_ - buffer_begin_);
  std::memcpy(ptr, buffer_.data() + buffer_begin_, n);
  buffer_begin_ += n;
  body_bytes_ += n;
  return ssize_t(n);
}

bool ConnectionStream::send_all(const char* data, std::size_t size, Clock::time_point deadline) {
  while (size > 0) {
    const ssize_t n = ::send(sock_, data, size, MSG_DONTWAIT | MSG_NOSIGNAL);
    if (n > 0) {
      data += n;
      size -= std::size_t(n);
      continue;
    }
    if (n < 0 && errno == EINTR) continue;
    if (n < 0 && errno != EAGAIN && errno != EWOULDBLOCK) return false;
    pollfd p{sock_, POLLOUT, 0};
    const int r = ::poll(&p, 1, ms_until(deadline));
    if (r == 0) return false;  // the reader is slower than the minimum rate
    if (r < 0 && errno != EINTR) return false;
  }
  return true;
}

ssize_t ConnectionStream::write(const char* ptr, size_t size) {
  if (rejection_) {
    // The library answers a failed read with its own 400 or 404: ours goes out instead.
    flush_rejection();
    return ssize_t(size);
  }
  if (broken_) return -1;
  if (phase_ == Phase::kBody && size >= 10 && std::memcmp(ptr, "HTTP/1.1 1", 10) == 0) {
    // An interim answer ("100 Continue" to Expect: 100-continue), written in one piece before
    // the body is read: the request goes on, its body still to come.
    if (!send_all(ptr, size, rate_deadline(Clock::now(), limits_.write_grace_seconds, size))) {
      broken_ = true;
      return -1;
    }
    return ssize_t(size);
  }
  if (phase_ != Phase::kResponse) {
    if (phase_ == Phase::kHead || body_bytes_ < content_length_) must_close_ = true;
    phase_ = Phase::kResponse;
    write_start_ = Clock::now();
    written_ = 0;
  }
  if (!send_all(ptr, size,
                rate_deadline(write_start_, limits_.write_grace_seconds, written_ + size))) {
    broken_ = true;
    return -1;
  }
  written_ += size;
  return ssize_t(size);
}

void ConnectionStream::flush_rejection() {
  if (!rejection_ || rejection_sent_) return;
  rejection_sent_ = true;
  const Problem& p = *rejection_;
  const std::string body =
      problem_json(p, "").dump(-1, ' ', false, nlohmann::ordered_json::error_handler_t::replace);
  std::string head = "HTTP/1.1 " + std::to_string(p.status) + " " + status_reason(p.status) +
                     "\r\nContent-Type: application/problem+json\r\nContent-Length: " +
                     std::to_string(body.size()) + "\r\nConnection: close\r\n\r\n";
  head += body;
  send_all(head.data(), head.size(), Clock::now() + std::chrono::seconds(1));
}

bool ConnectionStream::is_readable() const {
  if (buffer_begin_ < buffer_end_) return true;
  pollfd p{sock_, POLLIN, 0};
  return ::poll(&p, 1, 0) > 0;
}

bool ConnectionStream::is_writable() const { return !broken_ && !rejection_; }

void ConnectionStream::get_remote_ip_and_port(std::string& ip, int& port) const {
  sockaddr_storage addr{};
  socklen_t len = sizeof addr;
  if (::getpeername(sock_, reinterpret_cast<sockaddr*>(&addr), &len) == 0)
    numeric_name(addr, len, ip, port);
}

void ConnectionStream::get_local_ip_and_port(std::string& ip, int& port) const {
  sockaddr_storage addr{};
  socklen_t len = sizeof addr;
  if (::getsockname(sock_, reinterpret_cast<sockaddr*>(&addr), &len) == 0)
    numeric_name(addr, len, ip, port);
}

// The library's only use of this is to refuse descriptors select() cannot watch (Debian builds it
// without CPPHTTPLIB_USE_POLL); this stream waits with poll(), so any descriptor works.
socket_t ConnectionStream::socket() const { return sock_ < FD_SETSIZE ? sock_ : 0; }

}  // namespace penumbra::server
