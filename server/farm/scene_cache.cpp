#include "server/farm/scene_cache.h"

namespace penumbra::server {

std::string scene_cache_key(const std::string& job_id, const std::optional<int64_t>& frame) {
  return frame ? job_id + "#" + std::to_string(*frame) : job_id;
}

void SceneCache::drop_released_locked() {
  for (auto it = entries_.begin(); it != entries_.end();) {
    if (!it->second.pending.valid() && it->second.ready.expired())
      it = entries_.erase(it);
    else
      ++it;
  }
}

SceneCache::Lookup SceneCache::get(const std::string& key, const Prepare& prepare) {
  std::unique_lock lock(mutex_);
  drop_released_locked();
  if (auto it = entries_.find(key); it != entries_.end()) {
    if (std::shared_ptr<const PreparedScene> held = it->second.ready.lock())
      return Lookup{std::move(held), {}, true};
    if (it->second.pending.valid()) {
      // Another slot is reading and building it: wait for that rather than build it twice.
      const std::shared_future<Lookup> pending = it->second.pending;
      lock.unlock();
      Lookup waited = pending.get();
      waited.reused = waited.scene != nullptr;
      return waited;
    }
  }
  std::promise<Lookup> promise;
  entries_[key].pending = promise.get_future().share();
  lock.unlock();

  Lookup made;
  try {
    made.scene = prepare(made.error);
  } catch (const std::exception& e) {
    made.scene.reset();
    made.error = e.what();
  } catch (...) {
    made.scene.reset();
    made.error = "unknown error";
  }
  if (!made.scene && made.error.empty()) made.error = "the scene could not be prepared";

  lock.lock();
  if (made.scene) {
    Entry& entry = entries_[key];
    entry.ready = made.scene;
    entry.pending = {};
  } else {
    entries_.erase(key);  // not kept: the next task of this scene tries again
  }
  lock.unlock();
  // Set after the entry is settled, so a slot that waited and one that comes later agree.
  promise.set_value(made);
  return made;
}

std::size_t SceneCache::live_entries() const {
  std::lock_guard lock(mutex_);
  std::size_t n = 0;
  for (const auto& [key, entry] : entries_)
    if (entry.pending.valid() || !entry.ready.expired()) ++n;
  return n;
}

}  // namespace penumbra::server
