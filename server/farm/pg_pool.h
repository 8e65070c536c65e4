#pragma once
// A few PostgreSQL connections shared by the HTTP threads of an API node: a request borrows one
// for its statements and gives it back. Bounded (PostgreSQL's max_connections is small, and
// every API node and worker holds some); a request waits for a free one.
#include <condition_variable>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "server/farm/pg_connection.h"

namespace penumbra::server {

class PgPool {
 public:
  PgPool(std::string url, int max_connections);

  class Lease {
   public:
    Lease(PgPool& pool, std::unique_ptr<PgConnection> conn) : pool_(pool), conn_(std::move(conn)) {}
    ~Lease() { pool_.give_back(std::move(conn_)); }
    Lease(const Lease&) = delete;
    Lease& operator=(const Lease&) = delete;
    PgConnection* operator->() { return conn_.get(); }
    PgConnection& operator*() { return *conn_; }

   private:
    PgPool& pool_;
    std::unique_ptr<PgConnection> conn_;
  };
  // Throws StoreError when no connection can be opened.
  Lease acquire();
  const std::string& url() const { return url_; }

 private:
  void give_back(std::unique_ptr<PgConnection> conn);
  std::string url_;
  int max_;
  std::mutex mutex_;
  std::condition_variable freed_;
  std::vector<std::unique_ptr<PgConnection>> idle_;
  int open_ = 0;
};

}  // namespace penumbra::server
