// libFuzzer target: arbitrary bytes through the scene loader (JSON parse, typed parse,
// validation, conversion). Bad scenes must give errors, never crashes, hangs, leaks or
// undefined behaviour (the build adds ASan and UBSan). Valid scenes are also built into a
// renderer Scene (Embree BVH, light sampler) and rendered at 4x4 pixels, 1 sample, so the
// conversion's output is exercised by the code that trusts it.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "api/animation_parser.h"
#include "api/scene_loader.h"
#include "renderer/render/render.h"
#include "renderer/scene/scene.h"

namespace {

// Small caps keep each input fast; the limits' own boundaries are covered by tests/api.
penumbra::api::Limits fuzz_limits() {
  penumbra::api::Limits l;
  l.max_width = 64;
  l.max_height = 64;
  l.max_pixels = 64 * 64;
  l.max_spp = 16;
  l.max_depth = 16;
  l.max_triangles = 20'000;
  l.max_objects = 200;
  l.max_instances = 200;
  l.max_materials = 64;
  l.max_lights = 64;
  l.max_json_depth = 32;
  return l;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  const penumbra::api::LoadResult result = penumbra::api::load_scene(text, fuzz_limits());
  // The result's invariants: a request iff no errors; every error names a JSON pointer.
  if (result.ok() != result.request.has_value()) std::abort();
  for (const auto& e : result.errors)
    if (!e.pointer.empty() && e.pointer[0] != '/') std::abort();
  if (!result.ok()) return 0;

  // An animated scene renders its last frame: the loader checked motion over every frame's
  // shutter, so the frame farthest in time must build and render as well as the first.
  penumbra::api::SceneRequest request = *result.request;
  if (request.animation) {
    penumbra::api::Diagnostics diag;
    if (!penumbra::api::select_frame(request, request.animation->last_frame, diag)) std::abort();
  }
  const auto scene = penumbra::Scene::build(request.scene);
  penumbra::RenderSettings s = request.settings;
  s.width = 4;
  s.height = 4;
  // A window (checked against the scene's own size) becomes one inside the 4x4 image.
  if (s.window) s.window = penumbra::PixelWindow{1, 1, 3, 4};
  s.spp = 1;
  s.max_depth = std::min(s.max_depth < 0 ? 4 : s.max_depth, 4);
  s.threads = 1;
  s.noise_threshold = 0.f;
  s.time_limit = 0.0;
  const penumbra::RenderResult r = penumbra::render(*scene, s);
  for (float v : r.image.rgb)
    if (!std::isfinite(v)) std::abort();
  if (r.image.width != r.window.width() || r.image.height != r.window.height()) std::abort();
  return 0;
}
