#pragma once
// What a scene contains, decided once at build time so render code can skip what is absent
// (Cycles' kernel features).

namespace penumbra {

struct SceneFeatures {
  bool motion = false;        // any object with nonzero velocity or acceleration over the shutter
  bool lens = false;          // aperture_radius > 0
  bool transmission = false;  // any material that transmits
  bool absorption = false;    // any material that absorbs inside (Beer-Lambert)
  bool lights = false;        // any light to sample (area, point, directional or environment)
  bool mis_lights = false;    // any light the path integrator samples (Light::left_to_bsdf_sampling)
  bool environment = false;   // rays that escape see radiance
  bool textures = false;      // some material reads textures: hits need their uv
};

}  // namespace penumbra
