#include "server/http/guarded_server.h"

#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>

#include "server/http/connection_pool.h"
#include "server/http/connection_stream.h"
#include "server/http/problem.h"

namespace penumbra::server {
namespace {

thread_local int t_connection_socket = -1;

// Closes after the answer has had a chance to reach the client: closing a socket with unread
// input resets the connection, and the client may lose the answer with it (a rejected request
// usually has more head or body on the way). Reads and drops input for up to 1 s or 1 MB.
void lingering_close(socket_t sock) {
  ::shutdown(sock, SHUT_WR);
  char buf[16384];
  std::size_t dropped = 0;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(1);
  while (dropped < (1u << 20)) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
                          deadline - std::chrono::steady_clock::now())
                          .count();
    if (left <= 0) break;
    pollfd p{sock, POLLIN, 0};
    if (::poll(&p, 1, int(left)) <= 0) break;
    const ssize_t n = ::recv(sock, buf, sizeof buf, MSG_DONTWAIT);
    if (n <= 0) break;
    dropped += std::size_t(n);
  }
  ::close(sock);
}

}  // namespace

int current_connection_socket() { return t_connection_socket; }

GuardedServer::GuardedServer(const ConnectionLimits& limits, int listen_backlog, Metrics& metrics)
    : limits_(limits), listen_backlog_(listen_backlog), metrics_(metrics) {}

void GuardedServer::widen_backlog() {
  // listen() on a listening socket only changes its backlog (Linux); the kernel caps it at
  // net.core.somaxconn.
  if (svr_sock_ != INVALID_SOCKET) ::listen(svr_sock_, listen_backlog_);
}

void GuardedServer::shed(socket_t sock) {
  metrics_.count_connection_refused("overload");
  Problem p = make_problem(503, "overloaded", "Service Unavailable",
                           "the server has no connection thread free; retry shortly");
  p.retry_after_seconds = 1;
  const std::string body = problem_json(p, "").dump();
  const std::string answer =
      "HTTP/1.1 503 Service Unavailable\r\nContent-Type: application/problem+json\r\n"
      "Retry-After: 1\r\nConnection: close\r\nContent-Length: " +
      std::to_string(body.size()) + "\r\n\r\n" + body;
  // On the accepting thread: never wait for this client.
  (void)::send(sock, answer.data(), answer.size(), MSG_DONTWAIT | MSG_NOSIGNAL);
  ::shutdown(sock, SHUT_RDWR);
  ::close(sock);
}

bool GuardedServer::process_and_close_socket(socket_t sock) {
  if (ConnectionPool::is_shedding()) {
    shed(sock);
    return false;
  }
  ConnectionStream stream(sock, limits_);  // the first request's head deadline runs from accept
  // current_connection_socket() while this connection is served.
  struct SocketScope {
    explicit SocketScope(int s) { t_connection_socket = s; }
    ~SocketScope() { t_connection_socket = -1; }
  };
  const SocketScope socket_scope{int(sock)};
  const auto serving = [this] { return svr_sock_ != INVALID_SOCKET; };
  const auto first_wait = std::chrono::duration_cast<std::chrono::milliseconds>(
      std::chrono::duration<double>(limits_.header_seconds));
  const auto keep_alive = std::chrono::milliseconds(keep_alive_timeout_sec_ * 1000);
  bool ok = false;
  for (std::size_t count = keep_alive_max_count_; count > 0; --count) {
    const bool first = count == keep_alive_max_count_;
    if (!stream.wait_for_request(first ? first_wait : keep_alive, serving) || !serving()) break;
    if (!first) stream.begin_request();
    bool connection_closed = false;
    ok = process_request(stream, count == 1, connection_closed, nullptr);
    if (stream.rejected()) {
      stream.flush_rejection();
      metrics_.count_connection_refused("limit");
      lingering_close(sock);
      return false;
    }
    if (stream.must_close()) {
      lingering_close(sock);
      return ok;
    }
    if (!ok || connection_closed) break;
  }
  ::shutdown(sock, SHUT_RDWR);
  ::close(sock);
  return ok;
}

}  // namespace penumbra::server
