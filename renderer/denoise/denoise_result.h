#pragma once
// RenderSettings::denoise applied to a finished render: the image denoised by Open Image Denoise
// with the albedo and normal layers as guides, the image as rendered kept as the "noisy" layer
// (the unbiased one), and the guide layers the render was not asked for dropped again.
#include <cstdint>

#include "renderer/render/render.h"

namespace penumbra {

// `requested`: RenderSettings::outputs (the layers to keep). Fills stats.denoised,
// denoise_seconds and denoise_error; on failure the image stays as rendered, with no "noisy"
// layer, and the render still succeeds.
void denoise_result(uint32_t requested, RenderResult* result);

}  // namespace penumbra
