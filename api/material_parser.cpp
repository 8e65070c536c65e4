#include "api/material_parser.h"

#include "api/texture_parser.h"

namespace penumbra::api {

namespace {

// Reflectances: energy conservation needs each channel in [0, 1].
const Range kReflectance = Range::closed(0, 1);
const Range kRoughness = Range::closed(0, 1);
// ior == 1 (an invisible interface) is allowed on purpose: the stress suite renders it.
const Range kIor = Range::greater_than(0);

Spectrum to_spectrum(const glm::dvec3& v) { return Spectrum(float(v.x), float(v.y), float(v.z)); }

// A colour or roughness may be a constant or a texture: the texture's scale becomes the
// constant factor it multiplies (glTF's factor x texture).
template <typename P>
void read_color(ObjectReader& reader, P& p, TextureSet& textures) {
  if (auto c = read_spectrum_field(reader, "color", kReflectance, TextureRole::kReflectance, textures)) {
    p.color = c->factor;
    p.color_texture = c->texture;
  }
}
template <typename P>
void read_roughness(ObjectReader& reader, P& p, TextureSet& textures) {
  if (auto r = read_float_field(reader, "roughness", kRoughness, textures)) {
    p.roughness = r->factor;
    p.roughness_texture = r->texture;
  }
}

std::optional<MaterialParams> parse_material(const Json& value, const std::string& pointer,
                                             TextureSet& textures, Diagnostics& diag) {
  ObjectReader reader(value, pointer, diag);
  if (!reader.valid()) return std::nullopt;
  const std::size_t errors_before = diag.error_count();
  const auto type = reader.string("type", Presence::kRequired);
  if (!type) return std::nullopt;

  MaterialParams result;
  if (*type == "diffuse") {
    DiffuseParams p;
    read_color(reader, p, textures);
    p.normal_map = read_normal_map(reader, "normal_map", textures);
    result = p;
  } else if (*type == "conductor") {
    ConductorParams p;
    read_color(reader, p, textures);
    read_roughness(reader, p, textures);
    p.normal_map = read_normal_map(reader, "normal_map", textures);
    result = p;
  } else if (*type == "dielectric") {
    DielectricParams p;
    if (auto ior = reader.number("ior", kIor)) p.ior = float(*ior);
    read_roughness(reader, p, textures);
    if (auto a = reader.vec3("absorption", Range::at_least(0))) p.absorption = to_spectrum(*a);
    p.normal_map = read_normal_map(reader, "normal_map", textures);
    result = p;
  } else if (*type == "plastic") {
    PlasticParams p;
    read_color(reader, p, textures);
    if (auto ior = reader.number("ior", kIor)) p.ior = float(*ior);
    if (const Json* r = reader.get("roughness"); r && r->is_object()) {
      reader.error("roughness", "a plastic's roughness cannot be a texture: its coating's tables "
                                "are precomputed per roughness (as Mitsuba's roughplastic, whose "
                                "alpha is not texturable either); use a number");
    } else if (r) {
      if (auto v = read_number(*r, reader.pointer_of("roughness"), diag, kRoughness)) p.roughness = float(*v);
    }
    p.normal_map = read_normal_map(reader, "normal_map", textures);
    result = p;
  } else {
    reader.error("type", "unknown material type " + quote_user_string(*type) +
                             did_you_mean(*type, {"diffuse", "conductor", "dielectric", "plastic"}) +
                             "; expected diffuse, conductor, dielectric or plastic");
    return std::nullopt;  // the other keys cannot be judged without a type
  }
  reader.report_unknown_keys();
  if (diag.error_count() != errors_before) return std::nullopt;
  return result;
}

}  // namespace

ParsedMaterials parse_materials(const Json* materials, const std::string& pointer,
                                const Limits& limits, TextureSet& textures, Diagnostics& diag) {
  ParsedMaterials parsed;
  if (!materials) return parsed;
  if (!materials->is_object()) {
    diag.error(pointer, "must be an object mapping material names to materials");
    return parsed;
  }
  if (!within_count_limit(materials->size(), limits.max_materials, "materials", "max_materials",
                          pointer, diag))
    return parsed;
  for (const auto& [name, value] : materials->items()) {
    const auto material = parse_material(value, child_pointer(pointer, name), textures, diag);
    parsed.index[name] = uint32_t(parsed.names.size());
    parsed.names.push_back(name);
    // A placeholder keeps handles dense; it is never rendered because errors stop the load.
    parsed.params.push_back(material.value_or(DiffuseParams{}));
  }
  return parsed;
}

}  // namespace penumbra::api
