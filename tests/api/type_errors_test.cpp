// Wrong JSON types and missing required fields, each reported on the field's own pointer.
#include "tests/api/scene_test_util.h"

namespace penumbra::test {
namespace {

TEST(TypeErrors, WrongTypesNameTheField) {
  Json scene = base_scene();
  scene["render"] = {{"width", "256"}, {"integrator", 3}, {"seed", -1}};
  scene["camera"]["fov"] = true;
  scene["camera"]["up"] = {0, 1};
  scene["materials"]["white"]["color"] = {0.5, "x", 0.5};
  scene["objects"][0]["radius"] = nullptr;
  scene["objects"][0]["emission"] = 1;
  const LoadResult r = load(scene);
  EXPECT_EQ(r.kind, LoadErrorKind::kInvalid);
  EXPECT_ERROR(r, "/render/width", "must be an integer (got a string)");
  EXPECT_ERROR(r, "/render/integrator", "must be a string (got a number)");
  EXPECT_ERROR(r, "/render/seed", "must be >= 0");
  EXPECT_ERROR(r, "/camera/fov", "must be a number (got a boolean)");
  EXPECT_ERROR(r, "/camera/up", "must be an array of 3 numbers (got 2 elements)");
  EXPECT_ERROR(r, "/materials/white/color/1", "must be a number (got a string)");
  EXPECT_ERROR(r, "/objects/0/radius", "must be a number (got null)");
  EXPECT_ERROR(r, "/objects/0/emission", "must be an array of 3 numbers (got a number)");
}

TEST(TypeErrors, ContainersMustHaveTheirType) {
  Json scene = base_scene();
  scene["render"] = 1;
  scene["materials"] = Json::array();
  scene["objects"] = Json::object();
  scene["lights"] = "none";
  scene["environment"] = {1, 2, 3};
  const LoadResult r = load(scene);
  EXPECT_ERROR(r, "/render", "must be an object");
  EXPECT_ERROR(r, "/materials", "must be an object");
  EXPECT_ERROR(r, "/objects", "must be an array");
  EXPECT_ERROR(r, "/lights", "must be an array");
  EXPECT_ERROR(r, "/environment", "must be an object");
}

TEST(TypeErrors, ElementsOfArraysMustBeObjects) {
  Json scene = base_scene();
  scene["objects"].push_back(42);
  scene["lights"] = {"sun"};
  const LoadResult r = load(scene);
  EXPECT_ERROR(r, "/objects/1", "must be an object (got a number)");
  EXPECT_ERROR(r, "/lights/0", "must be an object (got a string)");
}

TEST(MissingFields, RequiredFieldsAreReportedWhereTheyBelong) {
  const LoadResult r = load_scene(R"({
    "camera": {"position": [0, 0, 1]},
    "materials": {"m": {"color": [1, 1, 1]}},
    "objects": [{"type": "sphere", "material": "m"}, {"type": "quad", "material": "m"},
                {"type": "mesh", "material": "m"}, {"center": [0, 0, 0]}],
    "lights": [{"type": "point"}, {"type": "directional"}, {}],
    "environment": {}
  })");
  EXPECT_ERROR(r, "/version", "required field is missing");
  EXPECT_ERROR(r, "/camera/look_at", "required field is missing");
  EXPECT_ERROR(r, "/materials/m/type", "required field is missing");
  EXPECT_ERROR(r, "/objects/0/center", "required field is missing");
  EXPECT_ERROR(r, "/objects/0/radius", "required field is missing");
  EXPECT_ERROR(r, "/objects/1/origin", "required field is missing");
  EXPECT_ERROR(r, "/objects/1/u", "required field is missing");
  EXPECT_ERROR(r, "/objects/1/v", "required field is missing");
  EXPECT_ERROR(r, "/objects/2/positions", "required field is missing");
  EXPECT_ERROR(r, "/objects/2/indices", "required field is missing");
  EXPECT_ERROR(r, "/objects/3/type", "required field is missing");
  EXPECT_ERROR(r, "/objects/3/material", "required field is missing");
  EXPECT_ERROR(r, "/lights/0/position", "required field is missing");
  EXPECT_ERROR(r, "/lights/0/intensity", "required field is missing");
  EXPECT_ERROR(r, "/lights/1/direction", "required field is missing");
  EXPECT_ERROR(r, "/lights/1/irradiance", "required field is missing");
  EXPECT_ERROR(r, "/lights/2/type", "required field is missing");
  EXPECT_ERROR(r, "/environment/radiance", "required field is missing");
}

TEST(MissingFields, CameraIsRequired) {
  Json scene = base_scene();
  scene.erase("camera");
  EXPECT_ERROR(load(scene), "/camera", "required field is missing");
}

TEST(MissingFields, VersionMustBeOne) {
  Json scene = base_scene();
  scene["version"] = 2;
  EXPECT_ERROR(load(scene), "/version", "unsupported scene format version 2");
  scene["version"] = "1";
  EXPECT_ERROR(load(scene), "/version", "must be an integer");
}

}  // namespace
}  // namespace penumbra::test
