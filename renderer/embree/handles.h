#pragma once
// Owning handles of Embree objects, so a scene build that fails half-way (an allocation that
// throws, an Embree error) releases everything it created.
#include <embree3/rtcore.h>

#include <utility>

namespace penumbra {

template <typename Handle, void (*kRelease)(Handle)>
class EmbreeHandle {
 public:
  EmbreeHandle() = default;
  explicit EmbreeHandle(Handle h) : h_(h) {}
  ~EmbreeHandle() { reset(); }
  EmbreeHandle(EmbreeHandle&& o) noexcept : h_(std::exchange(o.h_, nullptr)) {}
  EmbreeHandle& operator=(EmbreeHandle&& o) noexcept {
    if (this != &o) {
      reset();
      h_ = std::exchange(o.h_, nullptr);
    }
    return *this;
  }
  EmbreeHandle(const EmbreeHandle&) = delete;
  EmbreeHandle& operator=(const EmbreeHandle&) = delete;

  Handle get() const { return h_; }
  explicit operator bool() const { return h_ != nullptr; }
  // Gives up ownership.
  Handle release() { return std::exchange(h_, nullptr); }
  void reset() {
    if (h_) kRelease(h_);
    h_ = nullptr;
  }

 private:
  Handle h_ = nullptr;
};

using EmbreeGeometry = EmbreeHandle<RTCGeometry, rtcReleaseGeometry>;
using EmbreeScene = EmbreeHandle<RTCScene, rtcReleaseScene>;

}  // namespace penumbra
