// An "instances" object that copies what a gltf object placed at one of its file's nodes:
//   {"type": "instances", "mesh": {"object": 1, "node": "Tree"}, "transforms": [...]}
// (or {"object": 1, "mesh": m or "name"}: the first node that places that mesh). Each copy's
// transform applies after the node's placement, the object's transform included; a node of
// several primitives makes one set of copies per primitive.
#include <unistd.h>

#include <fstream>
#include <variant>

#include "renderer/render/render.h"
#include "renderer/scene/scene.h"
#include "tests/api/scene_test_util.h"
#include "tests/renderer/render/render_test_util.h"
#include "tests/renderer/io/gltf_test_util.h"

namespace penumbra::test {
namespace {

namespace fs = std::filesystem;

class GltfInstances : public ::testing::Test {
 protected:
  void SetUp() override {
    folder_.root =
        fs::temp_directory_path() / ("penumbra_gltf_instances_" + std::to_string(::getpid()));
    fs::create_directories(folder_.root);
  }
  void TearDown() override { fs::remove_all(folder_.root); }

  void write(const std::string& name, const std::vector<uint8_t>& bytes) {
    std::ofstream(folder_.root / name, std::ios::binary)
        .write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
  }
  // The base scene's sphere is /objects/0, the gltf object /objects/1, the instances /objects/2.
  LoadResult load_with(const Json& gltf_extra, const Json& mesh_selector, const Json& transforms) {
    Json scene = base_scene();
    Json gltf = {{"type", "gltf"}, {"file", "m.glb"}};
    gltf.update(gltf_extra);
    scene["objects"].push_back(gltf);
    scene["objects"].push_back(
        {{"type", "instances"}, {"mesh", mesh_selector}, {"transforms", transforms}});
    LoadResult r = load_scene(scene.dump(), {}, {}, folder_);
    if (r.request) restore_json_coordinates(*r.request);
    return r;
  }

  AssetFolder folder_;
};

// Where copy `k` of instances[i] puts the base object's vertex `v` (JSON coordinates).
vec3 copied_vertex(const SceneRequest& r, const InstancesDesc& d, std::size_t k, std::size_t v) {
  const auto& mesh = std::get<MeshDesc>(r.scene.objects[d.object].shape);
  const vec3 origin = vec3(r.world_origin);
  const InstanceTransform& t = d.transforms[k];
  return t.linear * (mesh.positions[v] - origin) + t.translation + origin;
}

// A "Tree" node at (0, 0, -1) and a second node "Copy" sharing its mesh at (0, 0, -3), scaled 2.
GltfBuilder tree_file() {
  GltfBuilder b;
  const int mesh = b.triangle();
  b.doc["meshes"][mesh]["name"] = "leaf";
  b.node({{"name", "Tree"}, {"mesh", mesh}, {"translation", {0, 0, -1}}});
  b.node({{"name", "Copy"}, {"mesh", mesh}, {"translation", {0, 0, -3}}, {"scale", {2, 2, 2}}});
  b.node({{"name", "Empty"}});
  return b;
}

TEST_F(GltfInstances, CopiesStartWhereTheNodePutsItsMeshAfterTheObjectTransform) {
  write("m.glb", tree_file().glb());
  // Rotating 90 degrees about +y after the placement: (x, y, z) -> (z, y, -x).
  const Json transforms = {{{"translate", {0, 5, 0}}},
                           {{"rotate", {{"axis", {0, 1, 0}}, {"degrees", 90}}}}};
  const LoadResult r = load_with({{"transform", {{"translate", {10, 0, 0}}}}},
                                 {{"object", 1}, {"node", "Tree"}}, transforms);
  ASSERT_TRUE(r.ok()) << describe(r.errors);
  const auto& instances = r.request->scene.instances;
  // The file's own shared mesh (node "Copy"), then the instances object's copies.
  ASSERT_EQ(instances.size(), 2u);
  const InstancesDesc& copies = instances[1];
  EXPECT_EQ(copies.object, 1u);  // the mesh where "Tree" stands
  ASSERT_EQ(copies.transforms.size(), 2u);
  // The file's vertex (1, 0, 0) stands at (11, 0, -1).
  const vec3 first = copied_vertex(*r.request, copies, 0, 1);
  EXPECT_NEAR(first.x, 11.f, 1e-4f);
  EXPECT_NEAR(first.y, 5.f, 1e-4f);
  EXPECT_NEAR(first.z, -1.f, 1e-4f);
  const vec3 second = copied_vertex(*r.request, copies, 1, 1);
  EXPECT_NEAR(second.x, -1.f, 1e-4f);
  EXPECT_NEAR(second.y, 0.f, 1e-4f);
  EXPECT_NEAR(second.z, -11.f, 1e-4f);
}

// A node that is itself a copy of the first node's placement: the instances copy the base object
// by the node's transform from there, then each copy's own.
TEST_F(GltfInstances, ANodeThatCopiesAnotherIsCopiedFromItsOwnPlacement) {
  write("m.glb", tree_file().glb());
  for (const Json& node : {Json("Copy"), Json(1)}) {
    const LoadResult r = load_with(Json::object(), {{"object", 1}, {"node", node}}, {{{"translate", {0, 5, 0}}}});
    ASSERT_TRUE(r.ok()) << describe(r.errors);
    const InstancesDesc& copies = r.request->scene.instances.back();
    EXPECT_EQ(copies.object, 1u);
    // Node "Copy" puts (1, 0, 0) at (2, 0, -3); the copy one up at (2, 5, -3).
    const vec3 v = copied_vertex(*r.request, copies, 0, 1);
    EXPECT_NEAR(v.x, 2.f, 1e-4f) << node;
    EXPECT_NEAR(v.y, 5.f, 1e-4f) << node;
    EXPECT_NEAR(v.z, -3.f, 1e-4f) << node;
  }
}

TEST_F(GltfInstances, AMeshIsCopiedFromTheFirstNodeThatPlacesIt) {
  write("m.glb", tree_file().glb());
  for (const Json& mesh : {Json("leaf"), Json(0)}) {
    const LoadResult r = load_with(Json::object(), {{"object", 1}, {"mesh", mesh}}, {{{"translate", {0, 5, 0}}}});
    ASSERT_TRUE(r.ok()) << describe(r.errors);
    const vec3 v = copied_vertex(*r.request, r.request->scene.instances.back(), 0, 1);
    EXPECT_NEAR(v.x, 1.f, 1e-4f) << mesh;
    EXPECT_NEAR(v.y, 5.f, 1e-4f) << mesh;
    EXPECT_NEAR(v.z, -1.f, 1e-4f) << mesh;
  }
}

// Each primitive of the node's mesh is an object; each gets the copies, and they count against
// max_instances.
TEST_F(GltfInstances, EveryPrimitiveOfTheNodeIsCopiedWithinTheInstanceLimit) {
  GltfBuilder b;
  const int mesh = b.triangle();
  b.doc["meshes"][mesh]["primitives"].push_back(b.doc["meshes"][mesh]["primitives"][0]);
  b.node({{"name", "Two"}, {"mesh", mesh}});
  write("m.glb", b.glb());
  const Json three = {{{"translate", {0, 1, 0}}}, {{"translate", {0, 2, 0}}}, {{"translate", {0, 3, 0}}}};
  const LoadResult r = load_with(Json::object(), {{"object", 1}, {"node", "Two"}}, three);
  ASSERT_TRUE(r.ok()) << describe(r.errors);
  ASSERT_EQ(r.request->scene.instances.size(), 2u);
  EXPECT_EQ(r.request->scene.instances[0].object, 1u);
  EXPECT_EQ(r.request->scene.instances[1].object, 2u);
  EXPECT_EQ(r.request->scene.instances[1].transforms.size(), 3u);

  Json scene = base_scene();
  scene["objects"].push_back({{"type", "gltf"}, {"file", "m.glb"}});
  scene["objects"].push_back(
      {{"type", "instances"}, {"mesh", {{"object", 1}, {"node", 0}}}, {"transforms", three}});
  Limits limits;
  limits.max_instances = 5;  // 3 as written, 6 placed
  const LoadResult over = load_scene(scene.dump(), limits, {}, folder_);
  EXPECT_TRUE(has(over.errors, "/objects/2/transforms", "max_instances")) << describe(over.errors);
  limits.max_instances = 6;
  const LoadResult at = load_scene(scene.dump(), limits, {}, folder_);
  EXPECT_TRUE(at.ok()) << describe(at.errors);
}

TEST_F(GltfInstances, SelectorsThatNameNothingUsableAreErrorsOnTheField) {
  GltfBuilder b = tree_file();
  b.node({{"name", "Tree"}, {"mesh", 0}, {"translation", {4, 0, 0}}});  // a second "Tree"
  b.doc["materials"] = Json::array({{{"emissiveFactor", {1, 1, 1}}}});
  const int glowing = b.triangle(0);
  b.node({{"name", "Lamp"}, {"mesh", glowing}});
  write("m.glb", b.glb());
  const Json one = {{{"translate", {0, 1, 0}}}};
  struct Case {
    Json selector;
    std::string pointer, words;
  };
  const std::vector<Case> cases = {
      {{{"object", 1}, {"node", "Tree"}}, "/objects/2/mesh", "several nodes named"},
      {{{"object", 1}, {"node", "Empty"}}, "/objects/2/mesh", "places no mesh"},
      {{{"object", 1}, {"node", 40}}, "/objects/2/mesh", "nodes[40]"},
      {{{"object", 1}, {"mesh", "bark"}}, "/objects/2/mesh", "no node"},
      {{{"object", 1}, {"node", "Lamp"}}, "/objects/2/mesh", "emits light"},
      {{{"object", 0}, {"node", 0}}, "/objects/2/mesh/object", "a sphere"},
      {{{"object", 9}, {"node", 0}}, "/objects/2/mesh/object", "out of range"},
      {{{"object", 1}, {"node", 0}, {"mesh", 0}}, "/objects/2/mesh/mesh", "not both"},
      {{{"object", 1}}, "/objects/2/mesh", "must name a glTF node or mesh"},
      {{{"object", 1}, {"node", ""}}, "/objects/2/mesh/node", "1 to 1024"},
      {{{"object", 1}, {"node", 0}, {"nod", 1}}, "/objects/2/mesh/nod", ""},
      {1, "/objects/2/mesh", "name one of its nodes or meshes"},
  };
  for (const Case& c : cases) {
    const LoadResult r = load_with(Json::object(), c.selector, one);
    EXPECT_TRUE(has(r.errors, c.pointer, c.words)) << c.selector << ": " << describe(r.errors);
  }
}

// Copies of a glTF node render as the same meshes placed by nodes of their own.
TEST_F(GltfInstances, CopiesRenderAsTheSameMeshPlacedByNodes) {
  const Json placement = {{"translation", {-0.5, -0.5, 0}}, {"scale", {1.5, 1.5, 1.5}}};
  GltfBuilder one, three;
  Json node = placement;
  node["mesh"] = one.triangle();
  node["name"] = "Shard";
  one.node(node);
  // The same placement, then translations by (1, 0.2, -1) and (-1, 0.5, 0.5).
  for (const glm::vec3 shift : {glm::vec3(0), glm::vec3(1, 0.2f, -1), glm::vec3(-1, 0.5f, 0.5f)}) {
    Json n = placement;
    n["translation"] = {-0.5 + shift.x, -0.5 + shift.y, shift.z};
    n["mesh"] = three.triangle();
    three.node(n);
  }
  write("one.glb", one.glb());
  write("three.glb", three.glb());
  auto render_scene = [&](const Json& objects) {
    Json scene = Json::parse(R"({"version": 1,
        "render": {"width": 32, "height": 24, "spp": 16, "seed": 7},
        "camera": {"position": [0.3, 0.4, 4], "look_at": [0, 0, 0], "fov": 50},
        "environment": {"radiance": [1, 1, 1]}, "materials": {}, "objects": []})");
    scene["objects"] = objects;
    const LoadResult r = load_scene(scene.dump(), {}, {}, folder_);
    EXPECT_TRUE(r.ok()) << describe(r.errors);
    if (!r.ok()) return Image();
    return render(*Scene::build(r.request->scene), r.request->settings).image;
  };
  const Image a = render_scene(Json::array(
      {{{"type", "gltf"}, {"file", "one.glb"}},
       {{"type", "instances"},
        {"mesh", {{"object", 0}, {"node", "Shard"}}},
        {"transforms", {{{"translate", {1, 0.2, -1}}}, {{"translate", {-1, 0.5, 0.5}}}}}}}));
  const Image b = render_scene(Json::array({{{"type", "gltf"}, {"file", "three.glb"}}}));
  EXPECT_LT(relative_l1(a, b), 2e-3);
}

}  // namespace
}  // namespace penumbra::test
