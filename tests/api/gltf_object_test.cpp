// The "gltf" object: a glTF asset from the scene's folder placed by its node hierarchy and then
// the object's transform, one object per mesh primitive at the first node that uses it and
// instances of it at the others, its materials as metallic_roughness materials after the scene's own,
// its lights added; every problem on the object's "file" field, naming the file.
#include <unistd.h>

#include <fstream>
#include <variant>

#include "renderer/render/render.h"
#include "renderer/scene/scene.h"
#include "tests/api/scene_test_util.h"
#include "tests/renderer/render/render_test_util.h"
#include "tests/renderer/io/gltf_test_util.h"
#include "tests/renderer/textures/texture_test_util.h"

namespace penumbra::test {
namespace {

namespace fs = std::filesystem;

class GltfObject : public ::testing::Test {
 protected:
  void SetUp() override {
    folder_.root = fs::temp_directory_path() / ("penumbra_gltf_object_" + std::to_string(::getpid()));
    fs::create_directories(folder_.root / "models");
  }
  void TearDown() override { fs::remove_all(folder_.root); }

  void write(const std::string& name, const std::vector<uint8_t>& bytes) {
    std::ofstream(folder_.root / name, std::ios::binary)
        .write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
  }
  LoadResult load_with(const std::string& file, const Json& extra = Json::object()) {
    Json scene = base_scene();
    Json object = {{"type", "gltf"}, {"file", file}};
    object.update(extra);
    scene["objects"].push_back(object);
    LoadResult r = load_scene(scene.dump(), {}, {}, folder_);
    if (r.request) restore_json_coordinates(*r.request);
    return r;
  }

  AssetFolder folder_;
};

GltfBuilder two_nodes_one_mesh() {
  GltfBuilder b;
  b.doc["materials"] = Json::array(
      {{{"pbrMetallicRoughness", {{"baseColorFactor", {0.8, 0.1, 0.1, 1}}, {"metallicFactor", 0}, {"roughnessFactor", 0.5}}}}});
  const int mesh = b.triangle(0);
  b.node({{"mesh", mesh}, {"translation", {0, 0, -1}}});
  b.node({{"mesh", mesh}, {"translation", {0, 0, -2}}});
  return b;
}

TEST_F(GltfObject, EachNodePlacesItsMeshWithTheObjectTransformOnTop) {
  write("models/m.glb", two_nodes_one_mesh().glb());
  const LoadResult r = load_with("models/m.glb", {{"transform", {{"translate", {10, 0, 0}}}}});
  ASSERT_TRUE(r.ok()) << describe(r.errors);
  const auto& objects = r.request->scene.objects;
  ASSERT_EQ(objects.size(), 2u);  // the base scene's sphere, then the mesh at the first node
  const auto& first = std::get<MeshDesc>(objects[1].shape);
  EXPECT_NEAR(first.positions[1].x, 11.f, 1e-5f);
  EXPECT_NEAR(first.positions[1].z, -1.f, 1e-5f);
  // The second node is an instance of it: one step further along -z.
  const auto& instances = r.request->scene.instances;
  ASSERT_EQ(instances.size(), 1u);
  EXPECT_EQ(instances[0].object, 1u);
  ASSERT_EQ(instances[0].transforms.size(), 1u);
  EXPECT_EQ(instances[0].transforms[0].linear, glm::mat3(1.f));
  EXPECT_NEAR(instances[0].transforms[0].translation.x, 0.f, 1e-6f);
  EXPECT_NEAR(instances[0].transforms[0].translation.z, -1.f, 1e-6f);
  EXPECT_EQ(first.uvs.size(), 3u);
  // Materials: the scene's "white", then the file's, then glTF's default material.
  ASSERT_EQ(r.request->scene.materials.size(), 3u);
  EXPECT_EQ(objects[1].material, 1u);
  const auto& m = std::get<MetallicRoughnessParams>(r.request->scene.materials[1]);
  EXPECT_EQ(m.color, Spectrum(0.8f, 0.1f, 0.1f));
  EXPECT_FLOAT_EQ(m.metallic, 0.f);
  EXPECT_FLOAT_EQ(m.roughness, 0.5f);
  ASSERT_EQ(r.request->assets.size(), 1u);
  EXPECT_NE(r.request->assets[0].summary.find("1 mesh at 2 nodes -> 1 triangle (+ 1 instanced copy)"),
            std::string::npos)
      << r.request->assets[0].summary;
}

// A mesh shared by nodes of both handedness: the mirrored nodes copy the first mirrored one (its
// triangles are re-wound), the others the first unmirrored one; the copy's transform maps the
// base's placement onto its own node's.
TEST_F(GltfObject, SharedMeshesBecomeInstancesPerHandedness) {
  GltfBuilder b;
  const int mesh = b.triangle();
  b.node({{"mesh", mesh}});
  b.node({{"mesh", mesh}, {"translation", {2, 0, 0}}, {"scale", {2, 2, 2}}});
  b.node({{"mesh", mesh}, {"scale", {-1, 1, 1}}});
  b.node({{"mesh", mesh}, {"translation", {0, 3, 0}}, {"scale", {-1, 1, 1}}});
  b.node({{"mesh", mesh}, {"translation", {0, 5, 0}}});
  write("m.gltf", b.gltf_bytes());
  const LoadResult r = load_with("m.gltf");
  ASSERT_TRUE(r.ok()) << describe(r.errors);
  const auto& objects = r.request->scene.objects;
  ASSERT_EQ(objects.size(), 3u);  // sphere, unmirrored base, mirrored base
  const auto& instances = r.request->scene.instances;
  ASSERT_EQ(instances.size(), 2u);
  EXPECT_EQ(instances[0].object, 1u);
  ASSERT_EQ(instances[0].transforms.size(), 2u);
  EXPECT_EQ(instances[0].transforms[0].linear, glm::mat3(2.f));
  EXPECT_NEAR(instances[0].transforms[0].translation.x, 2.f, 1e-6f);
  EXPECT_NEAR(instances[0].transforms[1].translation.y, 5.f, 1e-6f);
  EXPECT_EQ(instances[1].object, 2u);
  ASSERT_EQ(instances[1].transforms.size(), 1u);
  EXPECT_EQ(instances[1].transforms[0].linear, glm::mat3(1.f));  // mirror * mirror^-1
  EXPECT_NEAR(instances[1].transforms[0].translation.y, 3.f, 1e-6f);
  // Each copy lands where the node puts the mesh: the base's vertices mapped by the copy's
  // transform equal the node's transform of the file's vertices, (1, 0, 0) -> (4, 0, 0) here.
  const auto& base = std::get<MeshDesc>(objects[1].shape);
  const InstanceTransform& t = instances[0].transforms[0];
  const vec3 world_base = base.positions[1] - vec3(r.request->world_origin);
  const vec3 moved = t.linear * world_base + t.translation + vec3(r.request->world_origin);
  EXPECT_NEAR(moved.x, 4.f, 1e-5f);
  EXPECT_NEAR(moved.y, 0.f, 1e-5f);
}

// Emitting primitives and moving objects keep one copy of the mesh per node: an area light
// samples its own triangles, and a moving object's copies move by its velocity, not by the
// velocity mapped through each copy's transform.
TEST_F(GltfObject, EmittersAndMovingObjectsAreNotInstanced) {
  GltfBuilder b;
  b.doc["materials"] = Json::array({{{"emissiveFactor", {1, 1, 1}}}});
  const int mesh = b.triangle(0);
  b.node({{"mesh", mesh}});
  b.node({{"mesh", mesh}, {"translation", {2, 0, 0}}});
  write("emit.gltf", b.gltf_bytes());
  const LoadResult emitting = load_with("emit.gltf");
  ASSERT_TRUE(emitting.ok()) << describe(emitting.errors);
  EXPECT_EQ(emitting.request->scene.objects.size(), 3u);
  EXPECT_TRUE(emitting.request->scene.instances.empty());

  write("m.glb", two_nodes_one_mesh().glb());
  const LoadResult moving = load_with("m.glb", {{"velocity", {1, 0, 0}}});
  ASSERT_TRUE(moving.ok()) << describe(moving.errors);
  EXPECT_EQ(moving.request->scene.objects.size(), 3u);
  EXPECT_TRUE(moving.request->scene.instances.empty());
}

// Instances of a shared mesh render as the same meshes written out one per node: a file whose
// three nodes share a mesh against one whose nodes each have their own copy of it.
TEST_F(GltfObject, InstancedSharedMeshRendersAsCopies) {
  const std::vector<Json> nodes = {
      {{"translation", {-1.5, -0.5, 0}}, {"scale", {1.5, 1.5, 1.5}}},
      {{"translation", {0.5, -0.5, -1}}, {"rotation", {0, 0.3826834, 0, 0.9238795}}},
      {{"translation", {-0.5, 0.5, 0.5}}, {"scale", {1, 2, 0.5}}}};
  GltfBuilder shared, separate;
  const int one = shared.triangle();
  for (const Json& n : nodes) {
    Json with_mesh = n;
    with_mesh["mesh"] = one;
    shared.node(with_mesh);
    with_mesh["mesh"] = separate.triangle();
    separate.node(with_mesh);
  }
  write("shared.glb", shared.glb());
  write("separate.glb", separate.glb());
  auto render_file = [&](const std::string& file, std::size_t* instances) {
    Json scene = Json::parse(R"({"version": 1,
        "render": {"width": 32, "height": 24, "spp": 16, "seed": 7},
        "camera": {"position": [0.3, 0.4, 4], "look_at": [0, 0, 0], "fov": 50},
        "environment": {"radiance": [1, 1, 1]}, "materials": {}, "objects": []})");
    scene["objects"].push_back({{"type", "gltf"}, {"file", file}});
    const LoadResult r = load_scene(scene.dump(), {}, {}, folder_);
    EXPECT_TRUE(r.ok()) << describe(r.errors);
    if (!r.ok()) return Image();
    *instances = r.request->scene.instances.size();
    return render(*Scene::build(r.request->scene), r.request->settings).image;
  };
  std::size_t with_instances = 0, without = 0;
  const Image a = render_file("shared.glb", &with_instances);
  const Image b = render_file("separate.glb", &without);
  EXPECT_EQ(with_instances, 1u);
  EXPECT_EQ(without, 0u);
  // The same sampler values meet the same surfaces: only rounding in the rebuilt hit points
  // differs, which may turn a rare path; the images agree to well under a percent.
  EXPECT_LT(relative_l1(a, b), 2e-3);
}

TEST_F(GltfObject, MirroringTransformsKeepTheFrontFacesInFront) {
  GltfBuilder b;
  b.node({{"mesh", b.triangle()}, {"scale", {-1, 1, 1}}});
  write("m.gltf", b.gltf_bytes());
  const LoadResult r = load_with("m.gltf");
  ASSERT_TRUE(r.ok()) << describe(r.errors);
  const auto& mesh = std::get<MeshDesc>(r.request->scene.objects[1].shape);
  // The triangle's normal stays +z (counter-clockwise seen from +z) after the mirror.
  const vec3 n = glm::cross(mesh.positions[mesh.indices[1]] - mesh.positions[mesh.indices[0]],
                            mesh.positions[mesh.indices[2]] - mesh.positions[mesh.indices[0]]);
  EXPECT_GT(n.z, 0.f);
}

TEST_F(GltfObject, FilesItNamesMustStayInTheFolder) {
  GltfBuilder b;
  b.node({{"mesh", b.triangle()}});
  write("models/m.gltf", b.gltf_bytes("../../secret.bin"));
  EXPECT_ERROR(load_with("models/m.gltf"), "/objects/1/file", "'../../secret.bin': leaves the scene's folder");
  write("models/n.gltf", b.gltf_bytes("missing.bin"));
  EXPECT_ERROR(load_with("models/n.gltf"), "/objects/1/file", "'missing.bin': no such file");
  // A URI relative to the asset's own folder.
  write("models/data.bin", b.bin);
  write("models/ok.gltf", b.gltf_bytes("data.bin"));
  EXPECT_TRUE(load_with("models/ok.gltf").ok());
}

TEST_F(GltfObject, MaterialAndEmissionComeFromTheFile) {
  write("m.glb", two_nodes_one_mesh().glb());
  EXPECT_ERROR(load_with("m.glb", {{"material", "white"}}), "/objects/1/material", "from the file");
  EXPECT_ERROR(load_with("other.ply"), "/objects/1/file", ".gltf or .glb");
  EXPECT_ERROR(load_with("nothing.glb"), "/objects/1/file", "no such file");
}

TEST_F(GltfObject, PunctualLightsJoinTheScene) {
  GltfBuilder b;
  b.node({{"mesh", b.triangle()}});
  b.doc["extensionsUsed"] = {"KHR_lights_punctual"};
  b.doc["extensions"] = {{"KHR_lights_punctual",
                          {{"lights", Json::array({{{"type", "point"}, {"intensity", 5}},
                                                   {{"type", "directional"}, {"intensity", 2}}})}}}};
  b.node({{"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}, {"translation", {1, 2, 3}}});
  b.node({{"extensions", {{"KHR_lights_punctual", {{"light", 1}}}}}});
  write("m.gltf", b.gltf_bytes());
  const LoadResult r = load_with("m.gltf");
  ASSERT_TRUE(r.ok()) << describe(r.errors);
  ASSERT_EQ(r.request->scene.lights.size(), 2u);
  const auto& p = std::get<PointLightDesc>(r.request->scene.lights[0]);
  EXPECT_NEAR(p.position.y, 2.f, 1e-5f);
  EXPECT_EQ(p.intensity, Spectrum(5.f));
  const auto& d = std::get<DirectionalLightDesc>(r.request->scene.lights[1]);
  EXPECT_EQ(d.direction, vec3(0, 0, -1));  // glTF lights shine along their -z
  EXPECT_EQ(d.irradiance, Spectrum(2.f));
}

TEST_F(GltfObject, AlphaMaskBecomesACutoutOrLeavesThePrimitiveOut) {
  // An RGBA PNG embedded in the buffer as the base colour texture of a MASK material.
  const std::string png_path = (folder_.root / "rgba.png").string();
  write_test_image(png_path, 2, 2, 4, std::vector<float>(16, 0.5f), OIIO::TypeDesc::UINT8);
  std::ifstream in(png_path, std::ios::binary);
  const std::vector<uint8_t> png((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  GltfBuilder b;
  const int view = b.view(png.data(), png.size());
  b.doc["images"] = Json::array({{{"bufferView", view}, {"mimeType", "image/png"}}});
  b.doc["textures"] = Json::array({{{"source", 0}}});
  b.doc["materials"] = Json::array(
      {{{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}, {"baseColorFactor", {1, 1, 1, 0.8}}}},
        {"alphaMode", "MASK"}, {"alphaCutoff", 0.3}},
       {{"pbrMetallicRoughness", {{"baseColorFactor", {1, 1, 1, 0.2}}}}, {"alphaMode", "MASK"}}});
  b.node({{"mesh", b.triangle(0)}});
  b.node({{"mesh", b.triangle(1)}});
  write("m.glb", b.glb());
  const LoadResult r = load_with("m.glb");
  ASSERT_TRUE(r.ok()) << describe(r.errors);
  // The second primitive's alpha (0.2, no texture) is below its cutoff (0.5): left out.
  ASSERT_EQ(r.request->scene.objects.size(), 2u);
  const ObjectDesc& cut = r.request->scene.objects[1];
  ASSERT_TRUE(cut.alpha_texture);
  EXPECT_EQ(cut.alpha_texture->channel, 3);
  EXPECT_TRUE(cut.alpha_texture->bytes);
  EXPECT_FLOAT_EQ(cut.alpha_factor, 0.8f);
  EXPECT_FLOAT_EQ(cut.alpha_cutoff, 0.3f);
  EXPECT_TRUE(has(r.warnings, "/objects/1/file", "1 primitive left out"));
}

}  // namespace
}  // namespace penumbra::test
