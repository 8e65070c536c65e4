#include "api/scene_parser.h"

#include <algorithm>
#include <cmath>
#include <iterator>

#include "api/animation_parser.h"
#include "api/environment_parser.h"
#include "api/material_parser.h"
#include "api/object_parser.h"
#include "api/render_window.h"
#include "api/texture_parser.h"
#include "renderer/sampling/cmj.h"

namespace penumbra::api {

namespace {

constexpr int64_t kSupportedVersion = 1;

vec3 to_float(const glm::dvec3& v) { return vec3(float(v.x), float(v.y), float(v.z)); }

std::string limit_text(int64_t value, const char* name) {
  return "must be <= " + std::to_string(value) + " (" + name + ")";
}

// "outputs": ["albedo", "normal", "depth"], the output layers beside the beauty image
// (docs/output-layers.md). Each name once; an unknown one is an error with a suggestion.
void parse_outputs(const Json& outputs, const std::string& pointer, RenderSettings& settings,
                   Diagnostics& diag) {
  const std::vector<std::string> known(std::begin(kOutputLayerNames), std::end(kOutputLayerNames));
  if (!within_count_limit(outputs.size(), kOutputLayerCount, "outputs", "the number of output layers",
                          pointer, diag))
    return;
  uint32_t bits = 0;
  for (size_t i = 0; i < outputs.size(); ++i) {
    const std::string item = child_pointer(pointer, i);
    const auto name = read_string(outputs[i], item, diag);
    if (!name) continue;
    const auto it = std::find(known.begin(), known.end(), *name);
    if (it == known.end()) {
      diag.error(item, "unknown output layer " + quote_user_string(*name) + did_you_mean(*name, known) +
                           "; expected \"albedo\", \"normal\" or \"depth\"");
      continue;
    }
    const uint32_t bit = 1u << uint32_t(it - known.begin());
    if (bits & bit) diag.error(item, "output layer " + quote_user_string(*name) + " is listed twice");
    bits |= bit;
  }
  settings.outputs = bits;
}

void parse_render(const Json* value, const Limits& limits, RenderSettings& settings,
                  Diagnostics& diag) {
  if (!value) return;
  ObjectReader r(*value, "/render", diag);
  if (!r.valid()) return;
  if (auto w = r.integer("width", Range::at_least(1))) {
    if (*w > limits.max_width) r.error("width", limit_text(limits.max_width, "max_width"));
    else settings.width = int(*w);
  }
  if (auto h = r.integer("height", Range::at_least(1))) {
    if (*h > limits.max_height) r.error("height", limit_text(limits.max_height, "max_height"));
    else settings.height = int(*h);
  }
  if (int64_t(settings.width) * settings.height > limits.max_pixels)
    diag.error("/render", "width x height = " +
                              std::to_string(int64_t(settings.width) * settings.height) +
                              " pixels exceeds the limit of " + std::to_string(limits.max_pixels) +
                              " (max_pixels)");
  if (auto spp = r.integer("spp", Range::at_least(1))) {
    if (*spp > limits.max_spp) r.error("spp", limit_text(limits.max_spp, "max_spp"));
    else settings.spp = int(*spp);
  }
  if (auto depth = r.integer("max_depth")) {
    if (*depth != -1 && *depth < 1)
      r.error("max_depth", "must be >= 1, or -1 for unlimited");
    else if (*depth > limits.max_depth)
      r.error("max_depth", limit_text(limits.max_depth, "max_depth"));
    else
      settings.max_depth = int(*depth);
  }
  if (auto rr = r.integer("rr_depth", Range::at_least(1))) {
    if (*rr > limits.max_depth) r.error("rr_depth", limit_text(limits.max_depth, "max_depth"));
    else settings.rr_depth = int(*rr);
  }
  if (auto name = r.string("integrator")) {
    if (*name == "path")
      settings.integrator = IntegratorKind::kPath;
    else if (*name == "distributed")
      settings.integrator = IntegratorKind::kDistributed;
    else
      r.error("integrator", "unknown integrator " + quote_user_string(*name) +
                                did_you_mean(*name, {"path", "distributed"}) +
                                "; expected \"path\" or \"distributed\"");
  }
  if (auto seed = r.unsigned_integer("seed")) settings.seed = *seed;
  if (auto reuse = r.integer("path_reuse")) {
    if (*reuse < 1 || *reuse > RenderSettings::kMaxPathReuse)
      r.error("path_reuse", "must be 1 (off) to 4 (blocks of 4 x 4 pixels share their paths)");
    else
      settings.path_reuse = int(*reuse);
  }
  if (auto t = r.number("noise_threshold", Range::at_least(0))) settings.noise_threshold = float(*t);
  if (auto t = r.number("time_limit", Range::at_least(0))) {
    if (*t > limits.max_time_limit)
      r.error("time_limit", "must be <= " + format_number(limits.max_time_limit) +
                                " seconds (max_time_limit)");
    else
      settings.time_limit = *t;
  }
  // "auto": correlated multi-jittered points where every pixel takes spp samples, a power of two;
  // Sobol points where the count is decided as the render goes (adaptive sampling) or may be cut
  // short (a time budget: any prefix of a pixel's Sobol points is stratified, a prefix of CMJ's
  // is not), and at other counts (the first spp of the next power of two's CMJ points have more
  // variance than spp Sobol points: cornell 1.13 at 48 and 100 spp; docs/performance.md).
  // Resolved here, from the scene alone, so that a service's own cap on render time leaves
  // the job's image that of the command line.
  const std::optional<std::string> sampler = r.string("sampler");
  const bool power_of_two = cmj_takes_count(uint32_t(settings.spp));  // the renderer's own rule
  if (!sampler || *sampler == "auto")
    settings.sampler = settings.noise_threshold > 0.f || settings.time_limit > 0 || !power_of_two
                           ? SamplerKind::kSobol
                           : SamplerKind::kCorrelatedMultiJitter;
  else if (*sampler == "sobol")
    settings.sampler = SamplerKind::kSobol;
  else if (*sampler == "cmj" && settings.noise_threshold > 0.f)
    r.error("sampler", "\"cmj\" needs every pixel to take spp samples; adaptive sampling "
                       "(noise_threshold) takes \"sobol\" or \"auto\"");
  else if (*sampler == "cmj" && !power_of_two)
    r.error("sampler", "\"cmj\" needs spp to be a power of two (" + std::to_string(settings.spp) +
                           " is not); other counts take \"sobol\" or \"auto\"");
  else if (*sampler == "cmj")
    settings.sampler = SamplerKind::kCorrelatedMultiJitter;
  else
    r.error("sampler", "unknown sampler " + quote_user_string(*sampler) +
                           did_you_mean(*sampler, {"auto", "cmj", "sobol"}) +
                           "; expected \"auto\", \"cmj\" or \"sobol\"");
  if (const Json* outputs = r.array("outputs")) parse_outputs(*outputs, r.pointer_of("outputs"), settings, diag);
  if (const Json* denoise = r.get("denoise")) {
    if (denoise->is_boolean())
      settings.denoise = denoise->get<bool>();
    else
      r.error("denoise", "must be true or false");
  }
  if (const Json* window = r.get("window")) parse_render_window(*window, r.pointer_of("window"), settings, diag);
  // The denoiser looks at a neighbourhood of every pixel: denoised apart, windows would not join
  // into the image denoised whole. Merge first, then denoise (penumbra merge --denoise).
  if (settings.window && settings.denoise)
    r.error("denoise", "a window of the image cannot be denoised alone: render the windows without "
                       "denoise and denoise the merged image (penumbra merge --denoise)");
  r.report_unknown_keys();
}

// The renderer computes in single precision. A scene placed far from the origin (1e5, 1e6)
// would lose most of its float mantissa to the offset, so every position is expressed relative
// to the camera position, subtracted here in double precision: rendering is invariant under
// translation, and precision is then highest where the image is made. `origin` receives it.
void parse_camera(const Json* value, CameraDesc& camera, glm::dvec3& origin, Diagnostics& diag) {
  if (!value) {
    diag.error("/camera", "required field is missing");
    return;
  }
  ObjectReader r(*value, "/camera", diag);
  if (!r.valid()) return;
  const Range coordinate = Range::closed(-kMaxCoordinate, kMaxCoordinate);
  const auto position = r.vec3("position", coordinate, Presence::kRequired);
  const auto look_at = r.vec3("look_at", coordinate, Presence::kRequired);
  const auto up = r.vec3("up");
  const auto fov = r.number("fov", Range::open(0, 180));
  const auto aperture = r.number("aperture_radius", Range::at_least(0));
  const auto focus = r.number("focus_distance", Range::greater_than(0));
  if (const Json* shutter = r.get("shutter")) {
    if (shutter->is_array() && shutter->size() == 2) {
      const auto open = read_number((*shutter)[0], r.pointer_of("shutter") + "/0", diag);
      const auto close = read_number((*shutter)[1], r.pointer_of("shutter") + "/1", diag);
      if (open && close && *open > *close) {
        r.error("shutter", "must be [open, close] with open <= close");
      } else if (open && close) {
        camera.shutter_open = float(*open);
        camera.shutter_close = float(*close);
      }
    } else {
      r.error("shutter", "must be an array of 2 numbers [open, close]");
    }
  }
  r.report_unknown_keys();

  if (fov) camera.fov_degrees = float(*fov);
  if (aperture) camera.aperture_radius = float(*aperture);
  if (!position || !look_at) return;
  origin = *position;
  camera.position = vec3(0.f);
  camera.look_at = to_float(*look_at - origin);
  // Judge degeneracy in single precision: that is where the renderer builds its frame.
  const glm::dvec3 view = glm::dvec3(camera.look_at) - glm::dvec3(camera.position);
  const double distance = glm::length(view);
  if (!(distance > 0) || float(distance) == 0.f) {
    r.error("look_at", "must differ from position (the view direction would be undefined)");
    return;
  }
  if (up) {
    if (!(glm::length(*up) > 0)) {
      r.error("up", "must be a nonzero vector");
      return;
    }
    camera.up = to_float(glm::normalize(*up));
  }
  // sin of the angle between up and the view direction; below ~1e-4 the camera frame is
  // numerically meaningless in single precision.
  const double sine = glm::length(glm::cross(glm::normalize(view), glm::dvec3(camera.up)));
  if (!(sine > 1e-4)) {
    r.error(up ? "up" : "look_at",
            "is parallel to the view direction (look_at - position); the camera's roll is undefined");
    return;
  }
  camera.focus_distance = focus ? float(*focus) : float(distance);
}

void parse_lights(const Json* value, const Limits& limits, const glm::dvec3& origin,
                  std::vector<LightDesc>& lights,
                  bool& any_power, Diagnostics& diag) {
  if (!value) return;
  if (!value->is_array()) {
    diag.error("/lights", "must be an array of lights");
    return;
  }
  if (!within_count_limit(value->size(), limits.max_lights, "lights", "max_lights", "/lights", diag))
    return;
  const Range coordinate = Range::closed(-kMaxCoordinate, kMaxCoordinate);
  for (std::size_t i = 0; i < value->size(); ++i) {
    ObjectReader r((*value)[i], child_pointer("/lights", i), diag);
    if (!r.valid()) continue;
    const auto type = r.string("type", Presence::kRequired);
    if (!type) continue;
    if (*type == "point") {
      const auto position = r.vec3("position", coordinate, Presence::kRequired);
      const auto intensity = r.vec3("intensity", Range::at_least(0), Presence::kRequired);
      if (position && intensity) {
        lights.push_back(PointLightDesc{to_float(*position - origin), to_float(*intensity)});
        any_power |= !is_black(to_float(*intensity));
      }
    } else if (*type == "directional") {
      const auto direction = r.vec3("direction", Range::any(), Presence::kRequired);
      const auto irradiance = r.vec3("irradiance", Range::at_least(0), Presence::kRequired);
      if (direction && !(glm::length(*direction) > 0)) {
        r.error("direction", "must be a nonzero vector");
      } else if (direction && irradiance) {
        lights.push_back(
            DirectionalLightDesc{to_float(glm::normalize(*direction)), to_float(*irradiance)});
        any_power |= !is_black(to_float(*irradiance));
      }
    } else {
      r.error("type", "unknown light type " + quote_user_string(*type) +
                          did_you_mean(*type, {"point", "directional"}) +
                          "; expected point or directional");
      continue;
    }
    r.report_unknown_keys();
  }
}

}  // namespace

std::optional<SceneRequest> parse_scene(const Json& document, const Limits& limits,
                                        const AssetFolder& assets, Diagnostics& diag) {
  ObjectReader root(document, "", diag);
  if (!root.valid()) return std::nullopt;
  SceneRequest request;

  if (const auto version = root.integer("version", Range::any(), Presence::kRequired);
      version && *version != kSupportedVersion)
    root.error("version", "unsupported scene format version " + std::to_string(*version) +
                              "; this program reads version 1");
  // "$schema" lets editors find scene.schema.json; it has no meaning for rendering.
  root.string("$schema");

  parse_render(root.get("render"), limits, request.settings, diag);
  glm::dvec3 origin(0.0);
  parse_camera(root.get("camera"), request.scene.camera, origin, diag);

  std::vector<AssetUse> environment_files;
  const bool environment_lit =
      parse_environment(root.get("environment"), assets, request.scene, &environment_files, diag);

  TextureSet textures(limits, assets);
  ParsedMaterials materials =
      parse_materials(root.get("materials"), "/materials", limits, textures, diag);
  if (const Json* animation = root.get("animation")) {
    const Json* camera_json = root.get("camera");
    const bool camera_shutter = camera_json && camera_json->is_object() && camera_json->contains("shutter");
    request.animation = parse_animation(*animation, limits, camera_shutter, diag);
    // Consumers that know nothing of frames render the first one.
    if (request.animation) {
      const FrameShutter first = frame_shutter(*request.animation, request.animation->first_frame);
      request.scene.camera.shutter_open = float(first.open);
      request.scene.camera.shutter_close = float(first.close);
    }
  }
  const auto& camera = request.scene.camera;
  // Motion is checked over every frame's shutter, so any frame chosen later is in range.
  const double shutter_extent =
      request.animation ? animation_time_extent(*request.animation)
                        : std::max(std::abs(double(camera.shutter_open)), std::abs(double(camera.shutter_close)));
  ParsedObjects objects =
      parse_objects(root.get("objects"), "/objects", materials, shutter_extent, origin, limits,
                    assets, textures, diag);

  bool lights_lit = false;
  parse_lights(root.get("lights"), limits, origin, request.scene.lights, lights_lit, diag);
  // glTF assets' lights follow the scene's own.
  for (const LightDesc& light : objects.lights) {
    if (int64_t(request.scene.lights.size()) >= limits.max_lights) {
      diag.error("/objects", "the lights of the gltf objects bring the scene's lights beyond " +
                                 std::to_string(limits.max_lights) + " (max_lights)");
      break;
    }
    request.scene.lights.push_back(light);
    std::visit([&](const auto& l) {
      if constexpr (requires { l.intensity; }) lights_lit = lights_lit || !is_black(l.intensity);
      else lights_lit = lights_lit || !is_black(l.irradiance);
    }, light);
  }
  root.report_unknown_keys();
  if (diag.has_errors()) return std::nullopt;

  for (std::size_t m = 0; m < materials.names.size(); ++m)
    if (!objects.material_used[m])
      diag.warning(child_pointer("/materials", materials.names[m]), "material is never used");
  if (!objects.any_emission && !lights_lit && !environment_lit)
    diag.warning("", "the scene has no light source (no emission, no lights with power, black "
                     "environment): the image will be black");

  request.world_origin = origin;
  request.scene.materials = std::move(materials.params);
  request.scene.materials.insert(request.scene.materials.end(), objects.extra_materials.begin(),
                                 objects.extra_materials.end());
  request.scene.objects = std::move(objects.objects);
  request.scene.instances = std::move(objects.instances);
  request.assets = std::move(environment_files);
  request.assets.insert(request.assets.end(), textures.uses().begin(), textures.uses().end());
  request.assets.insert(request.assets.end(), objects.assets.begin(), objects.assets.end());
  request.texture_bytes = textures.bytes();
  request.scene.texture_limits = textures.renderer_limits();
  return request;
}

}  // namespace penumbra::api
