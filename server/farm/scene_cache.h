#pragma once
// The scenes a farm worker has read and built, shared by its tasks. The tiles of a split frame
// each render a window of one scene: without sharing, every tile read the scene's files, parsed
// them and built the Embree scene and the sampling tables again (for a 1M-triangle mesh about
// 0.5 s a tile, docs/scale-out.md "One scene per worker"). A worker now prepares a job's scene
// (a frame's, for an animation) once; its slots render their tiles from the same immutable
// Scene, which render() only reads.
//
// How long a scene lives: while a task renders it or a slot keeps it for its next task (a slot
// keeps the scene of its last task until it claims a task of another scene, or runs out of
// work), as a render farm's worker keeps a job's scene loaded between its tasks. A failure is
// not kept: the next task tries again (another attempt may find what this one lacked).
#include <functional>
#include <future>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>

#include "renderer/scene/scene.h"
#include "renderer/scene/scene_input.h"

namespace penumbra::server {

// A request read, validated and built, ready for its pieces' renders.
struct PreparedScene {
  RenderSettings settings;              // the request's (its frame chosen), before any piece's
  std::unique_ptr<const Scene> scene;   // never null
  double build_seconds = 0;             // Scene::build and the sampling tables
};

class SceneCache {
 public:
  struct Lookup {
    std::shared_ptr<const PreparedScene> scene;  // null when it could not be prepared: `error`
    std::string error;
    bool reused = false;  // prepared by an earlier task or by another slot of this worker
  };
  // Prepares a scene; returns null and sets `error` when it cannot.
  using Prepare = std::function<std::shared_ptr<const PreparedScene>(std::string& error)>;

  // The scene of `key`: one a task or slot of this worker still holds, or one another slot is
  // preparing (waited for), else prepared by `prepare` on this thread.
  Lookup get(const std::string& key, const Prepare& prepare);

  // Keys with a scene held or being prepared (tests).
  std::size_t live_entries() const;

 private:
  struct Entry {
    std::weak_ptr<const PreparedScene> ready;
    std::shared_future<Lookup> pending;  // valid while a slot prepares it
  };
  void drop_released_locked();

  mutable std::mutex mutex_;
  std::map<std::string, Entry> entries_;
};

// The cache key of a job's scene: its id and the frame (an animation's), if any.
std::string scene_cache_key(const std::string& job_id, const std::optional<int64_t>& frame);

}  // namespace penumbra::server
