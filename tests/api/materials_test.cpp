// Material references and parameters reach SceneInput with the right handles.
#include <variant>

#include "tests/api/scene_test_util.h"

namespace penumbra::test {
namespace {

TEST(Materials, UnknownReferenceSuggestsClosestName) {
  Json scene = base_scene();
  scene["materials"]["gold"] = {{"type", "conductor"}};
  scene["objects"][0]["material"] = "gld";
  EXPECT_ERROR(load(scene), "/objects/0/material", "unknown material 'gld' (did you mean 'gold'?)");
}

TEST(Materials, ReferenceWithoutAnyMaterials) {
  Json scene = base_scene();
  scene.erase("materials");
  EXPECT_ERROR(load(scene), "/objects/0/material", "/materials defines none");
}

TEST(Materials, NamesAreEscapedInPointers) {
  Json scene = base_scene();
  scene["materials"]["a/b~c"] = {{"type", "diffuse"}, {"color", {2, 0, 0}}};
  scene["objects"][0]["material"] = "a/b~c";
  EXPECT_ERROR(load(scene), "/materials/a~1b~0c/color/0", "must be in [0, 1]");
}

TEST(Materials, AllTypesWithDefaultsAndHandles) {
  Json scene = base_scene();
  scene["materials"] = Json::parse(R"({
    "d": {"type": "diffuse"}, "c": {"type": "conductor"},
    "g": {"type": "dielectric", "absorption": [0.1, 0.2, 0.3]},
    "p": {"type": "plastic", "color": [0.1, 0.2, 0.6], "ior": 1.4, "roughness": 0.2}
  })");
  scene["objects"][0]["material"] = "d";
  for (const char* name : {"d", "c", "g", "p"})
    scene["objects"].push_back({{"type", "sphere"}, {"center", {0, 3, 0}}, {"radius", 1},
                                {"material", name}});
  const LoadResult r = load(scene);
  ASSERT_TRUE(r.ok()) << describe(r.errors);
  const SceneInput& s = r.request->scene;
  ASSERT_EQ(s.materials.size(), 4u);
  ASSERT_EQ(s.objects.size(), 5u);
  for (std::size_t i = 1; i < 5; ++i) {
    const MaterialParams& m = s.materials[s.objects[i].material];
    switch (i) {
      case 1: EXPECT_EQ(std::get<DiffuseParams>(m).color, Spectrum(0.5f)); break;
      case 2:
        EXPECT_EQ(std::get<ConductorParams>(m).color, Spectrum(1.f));
        EXPECT_EQ(std::get<ConductorParams>(m).roughness, 0.f);
        break;
      case 3: {
        const auto& g = std::get<DielectricParams>(m);
        EXPECT_EQ(g.ior, 1.5f);
        EXPECT_EQ(g.roughness, 0.f);
        EXPECT_EQ(g.absorption, Spectrum(0.1f, 0.2f, 0.3f));
        break;
      }
      case 4: {
        const auto& p = std::get<PlasticParams>(m);
        EXPECT_EQ(p.color, Spectrum(0.1f, 0.2f, 0.6f));
        EXPECT_EQ(p.ior, 1.4f);
        EXPECT_EQ(p.roughness, 0.2f);
        break;
      }
    }
  }
}

TEST(Materials, UnusedMaterialIsAWarning) {
  Json scene = base_scene();
  scene["materials"]["spare"] = {{"type", "diffuse"}};
  const LoadResult r = load(scene);
  EXPECT_LOADS(r);
  EXPECT_TRUE(has(r.warnings, "/materials/spare", "never used")) << describe(r.warnings);
}

TEST(Materials, BrokenMaterialGivesOneErrorNotTwo) {
  Json scene = base_scene();
  scene["materials"]["white"]["color"] = {2, 2, 2};
  const LoadResult r = load(scene);
  EXPECT_FALSE(has(r.errors, "/objects/0/material")) << describe(r.errors);
  EXPECT_EQ(r.errors.size(), 3u) << describe(r.errors);
}

}  // namespace
}  // namespace penumbra::test
