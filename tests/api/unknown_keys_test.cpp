// Unknown keys are errors (they are usually typos of an optional field), with a suggestion.
#include "tests/api/scene_test_util.h"

namespace penumbra::test {
namespace {

TEST(UnknownKeys, AreErrorsWithSuggestions) {
  Json scene = base_scene();
  scene["rendr"] = Json::object();
  scene["camera"]["aperture"] = 0.1;
  scene["materials"]["white"]["roughnes"] = 0.2;
  scene["objects"][0]["emision"] = {1, 1, 1};
  scene["objects"][0]["transform"] = {{"translation", {0, 0, 0}}};
  scene["lights"] = {{{"type", "point"}, {"position", {0, 0, 0}}, {"intensity", {1, 1, 1}},
                      {"colour", 1}}};
  const LoadResult r = load(scene);
  EXPECT_ERROR(r, "/rendr", "unknown field 'rendr' (did you mean 'render'?)");
  EXPECT_ERROR(r, "/camera/aperture", "did you mean 'aperture_radius'?");
  EXPECT_ERROR(r, "/materials/white/roughnes", "unknown field 'roughnes'");
  EXPECT_ERROR(r, "/objects/0/emision", "did you mean 'emission'?");
  EXPECT_ERROR(r, "/objects/0/transform/translation", "did you mean 'translate'?");
  EXPECT_ERROR(r, "/lights/0/colour", "unknown field 'colour'");
}

TEST(UnknownKeys, FieldOfAnotherTypeIsUnknown) {
  Json scene = base_scene();
  scene["materials"]["white"]["ior"] = 1.5;  // diffuse has no ior
  scene["objects"][0]["origin"] = {0, 0, 0};  // spheres have no origin
  const LoadResult r = load(scene);
  EXPECT_ERROR(r, "/materials/white/ior", "unknown field 'ior'");
  EXPECT_ERROR(r, "/objects/0/origin", "unknown field 'origin'");
}

TEST(UnknownKeys, NoSuggestionWhenNothingIsClose) {
  Json scene = base_scene();
  scene["zzzzzzzz"] = 1;
  const LoadResult r = load(scene);
  EXPECT_ERROR(r, "/zzzzzzzz", "unknown field");
  EXPECT_FALSE(has(r.errors, "/zzzzzzzz", "did you mean"));
}

TEST(UnknownKeys, KeysWithSlashAndTildeAreEscaped) {
  Json scene = base_scene();
  scene["camera"]["a/b~c"] = 1;
  EXPECT_ERROR(load(scene), "/camera/a~1b~0c", "unknown field 'a/b~c'");
}

TEST(UnknownKeys, SchemaKeyIsAllowed) {
  Json scene = base_scene();
  scene["$schema"] = "https://example.org/scene.schema.json";
  EXPECT_LOADS(load(scene));
}

TEST(UnknownKeys, UnknownTypesSuggestTheClosest) {
  Json scene = base_scene();
  scene["materials"]["white"]["type"] = "difuse";
  scene["objects"][0]["type"] = "sphre";
  scene["lights"] = {{{"type", "pointt"}}};
  scene["render"] = {{"integrator", "pth"}};
  const LoadResult r = load(scene);
  EXPECT_ERROR(r, "/materials/white/type", "unknown material type 'difuse' (did you mean 'diffuse'?)");
  EXPECT_ERROR(r, "/objects/0/type", "unknown object type 'sphre' (did you mean 'sphere'?)");
  EXPECT_ERROR(r, "/lights/0/type", "unknown light type 'pointt' (did you mean 'point'?)");
  EXPECT_ERROR(r, "/render/integrator", "unknown integrator 'pth' (did you mean 'path'?)");
}

}  // namespace
}  // namespace penumbra::test
