// The wavefront driver's camera batch (render/camera_batch.cpp) against the scalar camera: the
// same rays to the bit, for pinhole and thin-lens cameras, any batch size.
#include <gtest/gtest.h>

#include <vector>

#include "renderer/render/thin_lens_camera.h"
#include "tests/bit_exact_util.h"

namespace penumbra::test {
namespace {

void expect_batch_is_scalar(const CameraDesc& desc, int width, int height) {
  const ThinLensCamera camera(desc, width, height);
  XorShift32 random{88172645u};
  auto uniform = [&random] { return random.uniform(); };
  for (size_t n : {1u, 5u, 16u, 33u, 300u}) {
    std::vector<float> fx(n), fy(n), lx(n), ly(n);
    for (size_t i = 0; i < n; ++i) {
      fx[i] = float(i % size_t(width)) + uniform();
      fy[i] = float((i * 7) % size_t(height)) + uniform();
      lx[i] = i == 3 ? 0.5f : uniform();  // the lens centre: the concentric map's special case
      ly[i] = i == 3 ? 0.5f : uniform();
    }
    std::vector<float> out_storage(6 * n);
    float* const out[6] = {&out_storage[0], &out_storage[n], &out_storage[2 * n],
                           &out_storage[3 * n], &out_storage[4 * n], &out_storage[5 * n]};
    camera.generate_rays(n, fx.data(), fy.data(), lx.data(), ly.data(), out);
    for (size_t i = 0; i < n; ++i) {
      const CameraRay ray = camera.generate_ray(vec2(fx[i], fy[i]), vec2(lx[i], ly[i]), 0.25f);
      for (int c = 0; c < 3; ++c) {
        ASSERT_EQ(float_bits(out[c][i]), float_bits(ray.origin[c])) << "n " << n << " ray " << i << " origin " << c;
        ASSERT_EQ(float_bits(out[3 + c][i]), float_bits(ray.direction[c])) << "n " << n << " ray " << i << " dir " << c;
      }
    }
  }
}

TEST(CameraBatch, PinholeRaysAreTheScalarOnesToTheBit) {
  CameraDesc desc;
  desc.position = vec3(0.3f, 1.1f, 3.6f);
  desc.look_at = vec3(-0.2f, 0.9f, 0.f);
  desc.fov_degrees = 37.f;
  expect_batch_is_scalar(desc, 97, 61);
}

TEST(CameraBatch, ThinLensRaysAreTheScalarOnesToTheBit) {
  CameraDesc desc;
  desc.position = vec3(0.3f, 1.1f, 3.6f);
  desc.look_at = vec3(-0.2f, 0.9f, 0.f);
  desc.fov_degrees = 52.f;
  desc.aperture_radius = 0.07f;
  desc.focus_distance = 3.3f;
  expect_batch_is_scalar(desc, 64, 128);
}

}  // namespace
}  // namespace penumbra::test
