#pragma once
// Test helper (header-only, as tests/server/*_test.cpp are the only compiled sources): runs the
// real `penumbra serve` binary on an ephemeral loopback port in a fresh data directory, and
// talks HTTP to it with cpp-httplib's client.
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <random>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include <httplib.h>
#include <nlohmann/json.hpp>

#include "test_support.h"

namespace penumbra::test {

namespace detail {
// fork + exec of the binary with stdout and stderr into one pipe; returns the read end.
inline pid_t spawn(const std::vector<std::string>& args, const std::vector<std::string>& env, int* out_fd) {
  int fds[2];
  if (::pipe2(fds, O_CLOEXEC) != 0) throw std::runtime_error("pipe");
  const pid_t pid = ::fork();
  if (pid < 0) throw std::runtime_error("fork");
  if (pid == 0) {
    ::dup2(fds[1], 1);
    ::dup2(fds[1], 2);
    for (const auto& e : env) ::putenv(const_cast<char*>(e.c_str()));
    std::vector<char*> argv;
    argv.push_back(const_cast<char*>(PENUMBRA_BINARY));
    argv.push_back(const_cast<char*>("serve"));
    for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    ::execv(PENUMBRA_BINARY, argv.data());
    ::_exit(127);
  }
  ::close(fds[1]);
  *out_fd = fds[0];
  return pid;
}
}  // namespace detail

class ServerProcess {
 public:
  // Starts `penumbra serve --port 0 --data-dir DIR <extra_args>` and waits for its
  // "listening on http://127.0.0.1:PORT" line. `env` entries are NAME=VALUE.
  ServerProcess(const std::string& data_dir, std::vector<std::string> extra_args = {},
                std::vector<std::string> env = {}) {
    std::vector<std::string> args = {"--port", "0", "--data-dir", data_dir};
    args.insert(args.end(), extra_args.begin(), extra_args.end());
    pid_ = detail::spawn(args, env, &fd_);
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
    while (port_ == 0 && std::chrono::steady_clock::now() < deadline) {
      if (!read_some(100)) {
        int status = 0;
        if (::waitpid(pid_, &status, WNOHANG) == pid_) {
          pid_ = -1;
          throw std::runtime_error("penumbra serve exited at startup: " + output_);
        }
      }
      const auto at = output_.find("listening on http://");
      if (at != std::string::npos && output_.find('\n', at) != std::string::npos) {
        const auto colon = output_.find(':', at + 20);
        port_ = std::stoi(output_.substr(colon + 1));
      }
    }
    if (port_ == 0) throw std::runtime_error("no listening line: " + output_);
    // Keep draining the pipe so the server never blocks on a full stderr.
    drain_ = std::thread([this] {
      while (fd_ >= 0 && read_some(200)) {
      }
    });
  }
  ~ServerProcess() {
    if (pid_ > 0) {
      ::kill(pid_, SIGKILL);
      ::waitpid(pid_, nullptr, 0);
    }
    if (drain_.joinable()) drain_.join();
    if (fd_ >= 0) ::close(fd_);
  }
  ServerProcess(const ServerProcess&) = delete;
  ServerProcess& operator=(const ServerProcess&) = delete;

  int port() const { return port_; }
  pid_t pid() const { return pid_; }
  std::unique_ptr<httplib::Client> client(const std::string& token = "") const {
    auto c = std::make_unique<httplib::Client>("127.0.0.1", port_);
    c->set_connection_timeout(5);
    c->set_read_timeout(60);
    c->set_write_timeout(10);
    if (!token.empty()) c->set_bearer_token_auth(token.c_str());
    return c;
  }
  void signal(int sig) const {
    if (pid_ > 0) ::kill(pid_, sig);
  }
  // The exit code (128 + signal when killed), or -1 on timeout.
  int wait_exit(std::chrono::milliseconds timeout) {
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    while (pid_ > 0) {
      int status = 0;
      if (::waitpid(pid_, &status, WNOHANG) == pid_) {
        pid_ = -1;
        return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
      }
      if (std::chrono::steady_clock::now() > deadline) return -1;
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    return -1;
  }

 private:
  // Reads what is available within timeout_ms; false on EOF.
  bool read_some(int timeout_ms) {
    pollfd p{fd_, POLLIN, 0};
    if (::poll(&p, 1, timeout_ms) <= 0) return true;
    char buf[4096];
    const ssize_t n = ::read(fd_, buf, sizeof buf);
    if (n <= 0) return false;
    if (port_ == 0) output_.append(buf, size_t(n));
    return true;
  }
  pid_t pid_ = -1;
  int port_ = 0;
  int fd_ = -1;
  std::string output_;
  std::thread drain_;
};

struct RunResult {
  int exit_code = -1;
  std::string output;  // stdout + stderr
};
// Runs `penumbra serve ARGS` to completion (for refusal tests); 10 s at most.
inline RunResult run_serve_to_exit(std::vector<std::string> args, std::vector<std::string> env = {}) {
  RunResult r;
  int fd = -1;
  const pid_t pid = detail::spawn(args, env, &fd);
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  char buf[4096];
  for (;;) {
    pollfd p{fd, POLLIN, 0};
    if (::poll(&p, 1, 100) > 0) {
      const ssize_t n = ::read(fd, buf, sizeof buf);
      if (n <= 0) break;
      r.output.append(buf, size_t(n));
    }
    if (std::chrono::steady_clock::now() > deadline) {
      ::kill(pid, SIGKILL);
      break;
    }
  }
  int status = 0;
  ::waitpid(pid, &status, 0);
  ::close(fd);
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  return r;
}

inline httplib::Result post_json(httplib::Client& client, const std::string& path,
                                 const std::string& body, const httplib::Headers& headers = {}) {
  return client.Post(path.c_str(), headers, body, "application/json");
}

inline std::string submit(httplib::Client& client, const Json& scene, int expected_status = 202) {
  auto res = post_json(client, "/v1/jobs", scene.dump());
  if (!res) throw std::runtime_error("POST /v1/jobs: no response");
  if (res->status != expected_status)
    throw std::runtime_error("POST /v1/jobs: " + std::to_string(res->status) + " " + res->body);
  return Json::parse(res->body).at("id").get<std::string>();
}

inline Json get_job(httplib::Client& client, const std::string& id) {
  auto res = client.Get(("/v1/jobs/" + id).c_str());
  if (!res) throw std::runtime_error("GET job: no response");
  if (res->status != 200) throw std::runtime_error("GET job: " + std::to_string(res->status));
  return Json::parse(res->body);
}

// Polls the job until its state is one of `states`; returns the last job document.
inline Json wait_for_state(httplib::Client& client, const std::string& id,
                           const std::vector<std::string>& states,
                           std::chrono::milliseconds timeout = std::chrono::seconds(60)) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  Json job;
  for (;;) {
    job = get_job(client, id);
    for (const auto& s : states)
      if (job["state"] == s) return job;
    if (std::chrono::steady_clock::now() > deadline) return job;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
}

}  // namespace penumbra::test

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>

namespace penumbra::test {

// Sends raw bytes on a fresh connection and returns whatever comes back within the timeout
// (for framing tests the client library would not produce: chunked bodies, bad lengths).
inline std::string raw_request(int port, const std::string& bytes, int timeout_ms = 3000) {
  const int fd = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(uint16_t(port));
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (::connect(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0) {
    ::close(fd);
    return "";
  }
  ::send(fd, bytes.data(), bytes.size(), MSG_NOSIGNAL);
  std::string out;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(timeout_ms);
  char buf[4096];
  while (std::chrono::steady_clock::now() < deadline) {
    pollfd p{fd, POLLIN, 0};
    if (::poll(&p, 1, 50) <= 0) {
      if (out.find("\r\n\r\n") != std::string::npos) break;  // a whole head and the body so far
      continue;
    }
    const ssize_t n = ::recv(fd, buf, sizeof buf, 0);
    if (n <= 0) break;
    out.append(buf, size_t(n));
  }
  ::close(fd);
  return out;
}

inline int raw_status(const std::string& response) {
  if (response.size() < 12 || response.compare(0, 5, "HTTP/") != 0) return -1;
  return std::stoi(response.substr(9, 3));
}

}  // namespace penumbra::test
