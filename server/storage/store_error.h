#pragma once
// The one exception type of the storage layer (a failed read, write or commit), whatever the
// backend.
#include <stdexcept>

namespace penumbra::server {

struct StoreError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

}  // namespace penumbra::server
