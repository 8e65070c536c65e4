#pragma once
// Errors the renderer reports to its callers.
#include <stdexcept>

namespace penumbra {

// A scene could not be built (Embree failed or ran out of memory). Input is validated before
// it reaches the renderer, so this is never the user's mistake in the scene file.
struct SceneBuildError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

}  // namespace penumbra
