#pragma once
// One libpq connection (PostgreSQL's C client; docs/design-notes.md says why not libpqxx):
// parameterised statements only (no SQL is ever built from a value), results as text, every
// failure a StoreError. A broken connection (server restarted, network cut) is reopened on the
// next call; the statement that saw the break fails, and its caller retries or answers 503.
#include <memory>
#include <optional>
#include <type_traits>
#include <string>
#include <vector>

#include "server/storage/store_error.h"

typedef struct pg_conn PGconn;
typedef struct pg_result PGresult;

namespace penumbra::server {

// A result's rows, text format: value() is "" for NULL (is_null tells them apart).
class PgRows {
 public:
  explicit PgRows(PGresult* result);
  ~PgRows();
  PgRows(PgRows&& other) noexcept;
  PgRows(const PgRows&) = delete;
  PgRows& operator=(const PgRows&) = delete;
  int size() const;
  int column(const char* name) const;  // throws StoreError when absent
  std::string value(int row, int column) const;
  std::string value(int row, const char* name) const { return value(row, column(name)); }
  bool is_null(int row, const char* name) const;
  long long int_value(int row, const char* name) const;
  double double_value(int row, const char* name) const;
  // Rows changed by an UPDATE/DELETE/INSERT.
  long long affected() const;

 private:
  PGresult* result_;
};

// A NULL parameter is nullopt.
using PgParam = std::optional<std::string>;

class PgConnection {
 public:
  // Connects at once; throws StoreError naming the failure (never the password).
  explicit PgConnection(std::string url);
  ~PgConnection();
  PgConnection(const PgConnection&) = delete;
  PgConnection& operator=(const PgConnection&) = delete;

  PgRows exec(const std::string& sql, const std::vector<PgParam>& params = {});
  // BEGIN ... COMMIT around `body`; ROLLBACK when it throws (then rethrown).
  template <typename F>
  auto transaction(F&& body) {
    exec("BEGIN");
    try {
      if constexpr (std::is_void_v<decltype(body())>) {
        body();
        exec("COMMIT");
      } else {
        auto result = body();
        exec("COMMIT");
        return result;
      }
    } catch (...) {
      rollback_quietly();
      throw;
    }
  }
  // LISTEN channel (again after every reconnect).
  void listen(const std::string& channel);
  // Waits up to `seconds` for a notification on a listened channel; true when one came (all
  // pending ones are consumed). A broken connection is reopened and answers true (a change may
  // have been missed meanwhile).
  bool wait_notification(double seconds);
  bool ok() const;

 private:
  void ensure_open();
  void rollback_quietly();
  std::string url_;
  PGconn* conn_ = nullptr;
  std::vector<std::string> listening_;
};

// The URL with any password replaced by "***", for log lines.
std::string redact_url(const std::string& url);

}  // namespace penumbra::server
