#pragma once
// What one client connection may cost the service, enforced by ConnectionStream while cpp-httplib
// parses (its own checks are per line and per read only, see docs/design-notes.md).
#include <cstddef>

namespace penumbra::server {

struct ConnectionLimits {
  std::size_t max_request_line = 8192;   // bytes, CR LF included; more -> 414
  std::size_t max_header_line = 8192;    // one field line, CR LF included; more -> 431
  std::size_t max_header_count = 100;    // field lines; more -> 431
  std::size_t max_header_bytes = 65536;  // request line + fields + blank line; more -> 431
  std::size_t max_range_bytes = 128;     // a Range value longer than any single range -> 416
  // The whole head (request line and fields) must arrive within this, however it trickles in:
  // a per-read timeout would be reset by every byte of a slowloris client.
  double header_seconds = 10.0;
  // A body, and a response, may take grace + bytes / min_rate seconds in all.
  double body_grace_seconds = 10.0;
  double write_grace_seconds = 30.0;
  double min_bytes_per_second = 8192.0;
};

}  // namespace penumbra::server
