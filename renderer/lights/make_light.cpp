#include "renderer/lights/make_light.h"

#include "renderer/lights/directional_light.h"
#include "renderer/lights/point_light.h"

namespace penumbra {
namespace {

// One line per light kind: its input struct and its class.
std::unique_ptr<Light> make(const PointLightDesc& d) { return std::make_unique<PointLight>(d.position, d.intensity); }
std::unique_ptr<Light> make(const DirectionalLightDesc& d) { return std::make_unique<DirectionalLight>(d.direction, d.irradiance); }

}  // namespace

std::unique_ptr<Light> make_light(const LightDesc& desc) {
  return std::visit([](const auto& d) { return make(d); }, desc);
}

}  // namespace penumbra
