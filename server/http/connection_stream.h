#pragma once
// One client connection as cpp-httplib sees it (an httplib::Stream), with the limits the library
// lacks: a total deadline for the request head however slowly it trickles in, caps on the head's
// lines, size and characters checked byte by byte as the library reads them (it reads the head one
// byte per call), and a minimum average rate for the body and the response. The stream lives as
// long as the connection, so bytes a client pipelines are kept between requests.
//
// A request over a limit is answered here with a problem document and the connection closed: the
// stream stops reading, swallows whatever answer the library then tries to write, and sends its
// own (flush_rejection).
#include <httplib.h>

#include <atomic>
#include <chrono>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "server/http/connection_limits.h"
#include "server/http/problem.h"

namespace penumbra::server {

class ConnectionStream : public httplib::Stream {
 public:
  using Clock = std::chrono::steady_clock;
  ConnectionStream(int sock, const ConnectionLimits& limits);

  // Starts a request: the head deadline runs from now.
  void begin_request();
  // Waits for the first byte of the next request (keep-alive); false on close, timeout, or when
  // keep_going() turns false (asked every 100 ms).
  bool wait_for_request(std::chrono::milliseconds timeout, const std::function<bool()>& keep_going);
  bool rejected() const { return rejection_.has_value(); }
  // True when the last answer went out before its request was read to the end (a head the
  // library could not parse, a body refused unread): what follows on the connection is not a
  // request, so it must be closed, not kept alive.
  bool must_close() const { return must_close_; }
  const std::optional<Problem>& rejection() const { return rejection_; }
  // Sends the rejection's problem document if the library has not made us send it yet.
  void flush_rejection();

  bool is_readable() const override;
  bool is_writable() const override;
  ssize_t read(char* ptr, size_t size) override;
  ssize_t write(const char* ptr, size_t size) override;
  void get_remote_ip_and_port(std::string& ip, int& port) const override;
  void get_local_ip_and_port(std::string& ip, int& port) const override;
  socket_t socket() const override;

 private:
  enum class Phase { kHead, kBody, kResponse };
  // Reads what the socket has into buffer_, waiting until deadline; -1 on error or timeout
  // (timed_out_ set), 0 at end of stream.
  ssize_t fill(Clock::time_point deadline);
  // Feeds one byte of the head through the checks; false when it rejected the request.
  bool on_head_byte(char c);
  void reject(Problem p);
  bool send_all(const char* data, std::size_t size, Clock::time_point deadline);
  Clock::time_point rate_deadline(Clock::time_point start, double grace, std::size_t bytes) const;

  int sock_;
  ConnectionLimits limits_;
  std::vector<char> buffer_;
  std::size_t buffer_begin_ = 0;
  std::size_t buffer_end_ = 0;

  Phase phase_ = Phase::kHead;
  Clock::time_point head_deadline_;
  std::string line_;            // the head line being received
  std::size_t line_index_ = 0;  // 0 = request line
  std::size_t head_bytes_ = 0;
  Clock::time_point body_start_;
  std::size_t body_bytes_ = 0;
  std::size_t content_length_ = 0;  // of the current request, from its head
  bool must_close_ = false;
  Clock::time_point write_start_;
  std::size_t written_ = 0;

  bool timed_out_ = false;
  bool broken_ = false;
  std::optional<Problem> rejection_;
  bool rejection_sent_ = false;
};

}  // namespace penumbra::server
