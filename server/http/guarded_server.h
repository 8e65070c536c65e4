#pragma once
// cpp-httplib's Server with its per-connection loop replaced: each connection is read through a
// ConnectionStream (total head deadline, head caps, minimum body and response rates) and served on
// a ConnectionPool thread, a connection the pool has no room for gets 503 at once, and the listen
// backlog is raised from the library's 5 (a burst of connects otherwise waits for SYN retries,
// 1 s, 3 s, ...: issue 15 item 8). Routing, handlers and response writing stay the library's,
// through its protected process_request().
#include <httplib.h>

#include <atomic>

#include "server/http/connection_limits.h"
#include "server/metrics.h"

namespace penumbra::server {

// The socket of the connection the calling thread serves (-1 outside one): a long response
// (an event stream) polls it to notice that its client has gone.
int current_connection_socket();

class GuardedServer : public httplib::Server {
 public:
  GuardedServer(const ConnectionLimits& limits, int listen_backlog, Metrics& metrics);
  // After bind_to_port / bind_to_any_port: widens the listen queue.
  void widen_backlog();
  // The listening socket (after a bind), e.g. to check the address it is bound to.
  socket_t listening_socket() const { return svr_sock_; }
  // False once stop() has begun: long responses end.
  bool serving() const { return svr_sock_ != INVALID_SOCKET; }

 private:
  bool process_and_close_socket(socket_t sock) override;
  void shed(socket_t sock);
  const ConnectionLimits limits_;
  const int listen_backlog_;
  Metrics& metrics_;
};

}  // namespace penumbra::server
