#pragma once
// Denoising with Intel Open Image Denoise (OIDN 2, Apache-2.0), loaded at run time. Debian 12
// does not package OIDN; scripts/install-oidn.sh takes its three shared libraries (the API, the
// core and the CPU device) from the pinned PyPI wheel pyoidn 2.5.1.0 and puts them, with OIDN's
// licence, in <prefix>/lib/penumbra/oidn/. They are looked for, in order:
//   $PENUMBRA_OIDN_DIR (a folder holding libOpenImageDenoise.so.2 and its two siblings)
//   <dir of the executable>/../lib/penumbra/oidn/   (build tree; installed prefix)
// Missing or failing, denoising says why and the caller keeps the image it has: a render never
// fails for want of a denoiser.
//
// The filter is OIDN's "RT" (ray-traced images) with `hdr` on: the input is linear radiance,
// not clamped. Albedo and normal layers (first-hit, averaged over each pixel's samples, as OIDN's
// documentation asks) make it keep texture and geometric detail; without them it denoises the
// colour alone.
#include <optional>
#include <string>
#include <vector>

namespace penumbra {

struct DenoiseInput {
  int width = 0, height = 0;
  const float* color = nullptr;   // RGB, width x height x 3, linear
  const float* albedo = nullptr;  // optional, RGB in [0, 1]
  const float* normal = nullptr;  // optional, world-space unit normals (needs albedo)
};

// The denoised RGB, or nullopt with `error` saying why (OIDN missing, its error message).
// Thread-safe; OIDN uses its own TBB-backed threads.
std::optional<std::vector<float>> denoise(const DenoiseInput& input, std::string* error);

// Whether OIDN can be loaded, and if not, why (for --version and /readyz-style reports).
bool denoiser_available(std::string* why = nullptr);

}  // namespace penumbra
