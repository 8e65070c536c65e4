#pragma once
// An allocator that leaves a trivial value it makes without an initialiser uninitialised:
// std::vector<T, DefaultInitAllocator<T>>::resize(n) allocates and writes nothing, so that the
// code that fills the array (in blocks on all cores) is the first to touch its pages and writes
// each value once. A std::vector<T> would zero it first, on one core (for an 8192 x 4096
// environment map's sampling table, 300 MB of page faults and writes in a row).
#include <memory>
#include <new>
#include <type_traits>
#include <utility>

namespace penumbra {

template <class T, class Base = std::allocator<T>>
class DefaultInitAllocator : public Base {
  using Traits = std::allocator_traits<Base>;

 public:
  template <class U>
  struct rebind {
    using other = DefaultInitAllocator<U, typename Traits::template rebind_alloc<U>>;
  };
  using Base::Base;

  template <class U>
  void construct(U* p) noexcept(std::is_nothrow_default_constructible_v<U>) {
    ::new (static_cast<void*>(p)) U;  // default-initialised: for a float, nothing is written
  }
  template <class U, class... Args>
  void construct(U* p, Args&&... args) {
    Traits::construct(static_cast<Base&>(*this), p, std::forward<Args>(args)...);
  }
};

}  // namespace penumbra
