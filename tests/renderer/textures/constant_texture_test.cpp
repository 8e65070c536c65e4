#include <gtest/gtest.h>

#include <memory>

#include "renderer/textures/constant_texture.h"

namespace penumbra::test {
namespace {

// Through the interface, a constant texture answers its value wherever and whenever it is asked.
TEST(ConstantTexture, SameValueAtEveryPoint) {
  const std::unique_ptr<SpectrumTexture> color = std::make_unique<ConstantSpectrumTexture>(Spectrum(0.1f, 0.2f, 0.3f));
  const std::unique_ptr<FloatTexture> roughness = std::make_unique<ConstantFloatTexture>(0.25f);
  for (const TextureQuery& q : {TextureQuery{}, TextureQuery{vec3(1e6f), vec2(0.5f, 2.f), 1.f}}) {
    EXPECT_EQ(color->eval(q), Spectrum(0.1f, 0.2f, 0.3f));
    EXPECT_EQ(roughness->eval(q), 0.25f);
  }
}

}  // namespace
}  // namespace penumbra::test
