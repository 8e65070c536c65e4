#include "server/farm/pg_pool.h"

namespace penumbra::server {

PgPool::PgPool(std::string url, int max_connections)
    : url_(std::move(url)), max_(std::max(1, max_connections)) {}

PgPool::Lease PgPool::acquire() {
  std::unique_lock lock(mutex_);
  freed_.wait(lock, [&] { return !idle_.empty() || open_ < max_; });
  if (!idle_.empty()) {
    std::unique_ptr<PgConnection> c = std::move(idle_.back());
    idle_.pop_back();
    return Lease(*this, std::move(c));
  }
  ++open_;
  lock.unlock();
  try {
    return Lease(*this, std::make_unique<PgConnection>(url_));
  } catch (...) {
    std::lock_guard again(mutex_);
    --open_;
    freed_.notify_one();
    throw;
  }
}

void PgPool::give_back(std::unique_ptr<PgConnection> conn) {
  if (!conn) return;
  std::lock_guard lock(mutex_);
  idle_.push_back(std::move(conn));
  freed_.notify_one();
}

}  // namespace penumbra::server
