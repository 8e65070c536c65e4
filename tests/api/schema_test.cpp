// api/scene.schema.json is compiled in, is valid JSON, and documents every field the loader reads.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "api/embedded_documents.h"

namespace penumbra::test {
namespace {

using namespace api;

using Json = nlohmann::json;

Json schema() {
  const std::string* text = embedded_document("scene.schema.json");
  EXPECT_NE(text, nullptr);
  return text ? Json::parse(*text) : Json();
}

// A member is documented by its own description or by that of the definition it refers to.
bool has_description(const Json& member) {
  if (member.contains("description")) return true;
  if (!member.contains("$ref")) return false;
  const std::string ref = member["$ref"];
  const Json s = schema();
  return s.contains(Json::json_pointer(ref.substr(1))) &&
         s[Json::json_pointer(ref.substr(1))].contains("description");
}

void expect_documented(const Json& properties, std::initializer_list<const char*> keys,
                       const std::string& where) {
  for (const char* key : keys) {
    ASSERT_TRUE(properties.contains(key)) << where << " lacks " << key;
    EXPECT_TRUE(has_description(properties[key])) << where << "/" << key;
  }
}

TEST(Schema, IsEmbeddedAndValidJson) {
  const Json s = schema();
  EXPECT_EQ(s["$schema"], "https://json-schema.org/draft/2020-12/schema");
  EXPECT_EQ(embedded_document("no-such-document.json"), nullptr);
}

TEST(Schema, DocumentsEveryField) {
  const Json s = schema();
  const Json& defs = s["$defs"];
  expect_documented(s["properties"],
                    {"version", "render", "camera", "animation", "environment", "materials", "objects", "lights"},
                    "root");
  expect_documented(defs["render"]["properties"],
                    {"width", "height", "spp", "max_depth", "rr_depth", "integrator", "seed",
                     "noise_threshold", "time_limit", "sampler", "outputs", "window"},
                    "render");
  expect_documented(defs["camera"]["properties"],
                    {"position", "look_at", "up", "fov", "aperture_radius", "focus_distance",
                     "shutter"},
                    "camera");
  expect_documented(defs["object"]["properties"],
                    {"type", "material", "emission", "velocity", "acceleration", "transform",
                     "center", "radius", "origin", "u", "v", "positions", "indices", "normals",
                     "uvs", "file", "mesh", "transforms"},
                    "object");
  const Json& materials = defs["material"]["oneOf"];
  expect_documented(materials[0]["properties"], {"type", "color", "normal_map"}, "diffuse");
  expect_documented(materials[1]["properties"], {"type", "color", "roughness", "normal_map"}, "conductor");
  expect_documented(materials[2]["properties"], {"type", "ior", "roughness", "absorption", "normal_map"},
                    "dielectric");
  expect_documented(materials[3]["properties"], {"type", "color", "ior", "roughness", "normal_map"}, "plastic");
  expect_documented(defs["texture"]["properties"],
                    {"texture", "colorspace", "channel", "scale", "wrap", "filter"}, "texture");
  expect_documented(defs["transform"]["oneOf"][0]["properties"], {"scale", "rotate", "translate"}, "transform");
  expect_documented(defs["transform"]["oneOf"][1]["properties"], {"matrix"}, "transform matrix");
  expect_documented(defs["light"]["oneOf"][0]["properties"], {"type", "position", "intensity"}, "point");
  expect_documented(defs["light"]["oneOf"][1]["properties"], {"type", "direction", "irradiance"}, "directional");
}

}  // namespace
}  // namespace penumbra::test
