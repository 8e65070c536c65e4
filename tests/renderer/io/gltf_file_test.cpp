// glTF 2.0 reading (renderer/io/gltf_file.h): meshes and the node hierarchy as stored, the GLB
// container, materials; and hostile input: every malformed or lying file is a GltfError naming
// the file and the element, never a crash or a runaway allocation.
#include "renderer/io/gltf_file.h"

#include <gtest/gtest.h>

#include "tests/renderer/io/gltf_test_util.h"

namespace penumbra::test {
namespace {

using json = nlohmann::json;

const GltfFileSource kNoFiles = [](const std::string&, std::vector<uint8_t>*, std::string* why) {
  *why = "no files in this test";
  return false;
};

GltfAsset read(const std::vector<uint8_t>& bytes, const GltfFileSource& files = kNoFiles) {
  return read_gltf(bytes, "'t.gltf'", files);
}

void expect_error(const std::vector<uint8_t>& bytes, const std::string& part,
                  const GltfFileSource& files = kNoFiles, const GltfLimits& limits = {}) {
  try {
    read_gltf(bytes, "'t.gltf'", files, limits);
    ADD_FAILURE() << "no error; expected one containing: " << part;
  } catch (const GltfError& e) {
    const std::string what = e.what();
    EXPECT_EQ(what.rfind("'t.gltf': ", 0), 0u) << what;
    EXPECT_NE(what.find(part), std::string::npos) << what;
  }
}

TEST(GltfFile, TriangleWithItsNodeTransform) {
  GltfBuilder b;
  const int mesh = b.triangle();
  b.node({{"mesh", mesh}, {"translation", {1, 2, 3}}, {"scale", {2, 2, 2}}});
  const GltfAsset a = read(b.gltf_bytes());
  ASSERT_EQ(a.meshes.size(), 1u);
  ASSERT_EQ(a.meshes[0].primitives.size(), 1u);
  const GltfPrimitive& p = a.meshes[0].primitives[0];
  EXPECT_EQ(p.positions[1], vec3(1, 0, 0));
  EXPECT_EQ(p.indices, (std::vector<uint32_t>{0, 1, 2}));
  EXPECT_EQ(p.uvs[2], vec2(0, 1));
  ASSERT_EQ(a.instances.size(), 1u);
  const glm::dvec4 w = a.instances[0].to_world * glm::dvec4(1, 0, 0, 1);
  EXPECT_EQ(glm::dvec3(w), glm::dvec3(3, 2, 3));
}

TEST(GltfFile, HierarchyComposesParentThenChildAndMeshesAreShared) {
  GltfBuilder b;
  const int mesh = b.triangle();
  const int child = b.node({{"mesh", mesh}, {"translation", {1, 0, 0}}}, false);
  // 90 degrees about +z: (x, y, z, w) = (0, 0, sin 45, cos 45).
  b.node({{"children", {child}}, {"rotation", {0, 0, std::sqrt(0.5), std::sqrt(0.5)}}});
  b.node({{"mesh", mesh}, {"matrix", {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 5, 0, 0, 1}}});
  const GltfAsset a = read(b.gltf_bytes());
  ASSERT_EQ(a.instances.size(), 2u);
  EXPECT_EQ(a.instances[0].mesh, a.instances[1].mesh);
  const glm::dvec3 p0(a.instances[0].to_world * glm::dvec4(0, 0, 0, 1));
  EXPECT_NEAR(p0.x, 0, 1e-12);
  EXPECT_NEAR(p0.y, 1, 1e-12);  // the child's +x offset turned to +y by the parent
  const glm::dvec3 p1(a.instances[1].to_world * glm::dvec4(0, 0, 0, 1));
  EXPECT_EQ(p1, glm::dvec3(5, 0, 0));  // column-major matrix: translation in the last column
}

TEST(GltfFile, GlbHoldsTheSameAsGltf) {
  GltfBuilder b;
  b.node({{"mesh", b.triangle()}});
  const GltfAsset from_glb = read(b.glb());
  const GltfAsset from_gltf = read(b.gltf_bytes());
  EXPECT_EQ(from_glb.meshes[0].primitives[0].positions, from_gltf.meshes[0].primitives[0].positions);
  EXPECT_EQ(from_glb.instances.size(), 1u);
}

TEST(GltfFile, StripsAndFansBecomeTriangles) {
  GltfBuilder b;
  const int m = b.mesh({0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0}, {0, 1, 2, 3});
  b.doc["meshes"][m]["primitives"][0]["mode"] = 5;  // strip
  const int f = b.mesh({0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0}, {0, 1, 2, 3});
  b.doc["meshes"][f]["primitives"][0]["mode"] = 6;  // fan
  b.node({{"mesh", m}});
  b.node({{"mesh", f}});
  const GltfAsset a = read(b.gltf_bytes());
  // Strip: (0 1 2), then (2 1 3) keeps the winding.
  EXPECT_EQ(a.meshes[0].primitives[0].indices, (std::vector<uint32_t>{0, 1, 2, 2, 1, 3}));
  EXPECT_EQ(a.meshes[1].primitives[0].indices, (std::vector<uint32_t>{0, 1, 2, 0, 2, 3}));
}

TEST(GltfFile, SparseAccessorsSubstitute) {
  GltfBuilder b;
  const int mesh = b.triangle();
  const uint32_t which[] = {1};
  const float value[] = {4, 5, 6};
  const int iv = b.view(which, 4), vv = b.view(value, 12);
  b.doc["accessors"][0]["sparse"] = {{"count", 1},
                                     {"indices", {{"bufferView", iv}, {"componentType", 5125}}},
                                     {"values", {{"bufferView", vv}}}};
  b.node({{"mesh", mesh}});
  EXPECT_EQ(read(b.gltf_bytes()).meshes[0].primitives[0].positions[1], vec3(4, 5, 6));
}

TEST(GltfFile, MaterialFactorsTexturesAndEmissiveStrength) {
  GltfBuilder b;
  b.doc["materials"] = json::array(
      {{{"pbrMetallicRoughness",
         {{"baseColorFactor", {0.5, 0.25, 1, 0.75}}, {"metallicFactor", 0.2}, {"roughnessFactor", 0.7}}},
        {"emissiveFactor", {1, 0.5, 0}},
        {"extensions", {{"KHR_materials_emissive_strength", {{"emissiveStrength", 4}}}}},
        {"alphaMode", "MASK"},
        {"alphaCutoff", 0.3}}});
  b.doc["extensionsUsed"] = {"KHR_materials_emissive_strength"};
  b.node({{"mesh", b.triangle(0)}});
  const GltfAsset a = read(b.gltf_bytes());
  ASSERT_EQ(a.materials.size(), 1u);
  const GltfMaterial& m = a.materials[0];
  EXPECT_EQ(m.base_color, Spectrum(0.5f, 0.25f, 1.f));
  EXPECT_FLOAT_EQ(m.alpha, 0.75f);
  EXPECT_FLOAT_EQ(m.metallic, 0.2f);
  EXPECT_FLOAT_EQ(m.roughness, 0.7f);
  EXPECT_EQ(m.emissive, Spectrum(4.f, 2.f, 0.f));
  EXPECT_EQ(m.alpha_mode, GltfAlphaMode::kMask);
  EXPECT_FLOAT_EQ(m.alpha_cutoff, 0.3f);
  EXPECT_TRUE(a.warnings.empty());
}

TEST(GltfFile, ImagesStayEncodedAndNamedFilesComeThroughTheSource) {
  GltfBuilder b;
  b.node({{"mesh", b.triangle(0)}});
  const std::vector<uint8_t> png = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n', 0, 0};
  b.doc["images"] = json::array({{{"uri", "tex.png"}}});
  b.doc["textures"] = json::array({{{"source", 0}}});
  b.doc["materials"] = json::array({{{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}}}}});
  std::vector<std::string> asked;
  const GltfFileSource files = [&](const std::string& uri, std::vector<uint8_t>* out, std::string*) {
    asked.push_back(uri);
    *out = uri == "tex.png" ? png : b.bin;
    return true;
  };
  const GltfAsset a = read(b.gltf_bytes("data.bin"), files);
  EXPECT_EQ(asked, (std::vector<std::string>{"data.bin", "tex.png"}));
  ASSERT_EQ(a.images.size(), 1u);
  EXPECT_EQ(a.images[0].extension, "png");
  EXPECT_EQ(*a.images[0].bytes, png);
  ASSERT_TRUE(a.materials[0].base_color_texture);
  EXPECT_EQ(a.materials[0].base_color_texture->image, 0);
}

TEST(GltfFile, AFileTheSourceRefusesIsAnErrorNamingIt) {
  GltfBuilder b;
  b.node({{"mesh", b.triangle()}});
  const GltfFileSource refuse = [](const std::string&, std::vector<uint8_t>*, std::string* why) {
    *why = "must stay inside the scene's folder";
    return false;
  };
  expect_error(b.gltf_bytes("../../etc/passwd"), "'../../etc/passwd': must stay inside", refuse);
  // An image, which tinygltf reports only as a warning, is an error too.
  GltfBuilder c;
  c.node({{"mesh", c.triangle()}});
  c.doc["images"] = json::array({{{"uri", "/etc/shadow.png"}}});
  expect_error(c.gltf_bytes(), "'/etc/shadow.png'", refuse);
}

TEST(GltfFile, LiesAndOutOfRangeIndicesAreErrors) {
  {
    GltfBuilder b;
    b.node({{"mesh", b.mesh({0, 0, 0, 1, 0, 0, 0, 1, 0}, {0, 1, 7})}});
    expect_error(b.gltf_bytes(), "meshes[0].primitives[0].indices: index 7");
  }
  {
    GltfBuilder b;
    b.node({{"mesh", b.triangle()}});
    b.doc["accessors"][0]["count"] = 4000000000u;  // a count that lies
    expect_error(b.gltf_bytes(), "POSITION");
  }
  {
    GltfBuilder b;
    b.node({{"mesh", b.triangle()}});
    b.doc["accessors"][0]["count"] = 100;  // within the limits, beyond its buffer view
    expect_error(b.gltf_bytes(), "bytes of a buffer view of 36");
  }
  {
    GltfBuilder b;
    b.node({{"mesh", b.triangle()}});
    b.doc["bufferViews"][0]["byteLength"] = 1000000;  // beyond its buffer
    expect_error(b.gltf_bytes(), "outside its buffer");
  }
  {
    GltfBuilder b;
    b.node({{"mesh", b.mesh({0, 0, 0, 1, 0, 0, 0, NAN, 0}, {0, 1, 2})}});
    expect_error(b.gltf_bytes(), "not a finite");
  }
}

TEST(GltfFile, TruncatedAndMalformedContainers) {
  GltfBuilder b;
  b.node({{"mesh", b.triangle()}});
  std::vector<uint8_t> glb = b.glb();
  expect_error(std::vector<uint8_t>(glb.begin(), glb.begin() + 30), "truncated GLB");
  std::vector<uint8_t> lying = glb;
  lying[12] = 0xff, lying[13] = 0xff;  // a JSON chunk longer than the file
  expect_error(lying, "JSON chunk");
  expect_error(std::vector<uint8_t>{'{', '"', 'a'}, "");
  std::string deep(100000, '[');
  expect_error(std::vector<uint8_t>(deep.begin(), deep.end()), "nested deeper than 64");
}

TEST(GltfFile, CyclesAndDepthInTheHierarchyAreErrors) {
  GltfBuilder b;
  b.node({{"children", {1}}});
  b.node({{"children", {0}}}, false);
  expect_error(b.gltf_bytes(), "(or has a cycle)");
}

TEST(GltfFile, RequiredUnsupportedExtensionsAreErrorsOptionalOnesWarnings) {
  GltfBuilder b;
  b.node({{"mesh", b.triangle()}});
  b.doc["extensionsUsed"] = {"KHR_draco_mesh_compression"};
  const GltfAsset a = read(b.gltf_bytes());
  ASSERT_EQ(a.warnings.size(), 1u);
  EXPECT_NE(a.warnings[0].find("KHR_draco_mesh_compression"), std::string::npos);
  b.doc["extensionsRequired"] = {"KHR_draco_mesh_compression"};
  expect_error(b.gltf_bytes(), "requires the extension KHR_draco_mesh_compression");
}

TEST(GltfFile, TriangleLimitHoldsBeforeAllocation) {
  GltfBuilder b;
  b.node({{"mesh", b.triangle()}});
  GltfLimits limits;
  limits.max_triangles = 0;
  expect_error(b.gltf_bytes(), "indices", kNoFiles, limits);
}

TEST(GltfFile, CamerasAndPunctualLightsArePlacedByTheirNodes) {
  GltfBuilder b;
  b.doc["cameras"] = json::array({{{"type", "perspective"}, {"perspective", {{"yfov", 0.5}, {"znear", 0.1}, {"aspectRatio", 2.0}}}}});
  b.doc["extensionsUsed"] = {"KHR_lights_punctual"};
  b.doc["extensions"] = {{"KHR_lights_punctual",
                          {{"lights", json::array({{{"type", "point"}, {"color", {1, 0.5, 0.25}}, {"intensity", 8}}})}}}};
  b.node({{"camera", 0}, {"translation", {0, 1, 5}}});
  b.node({{"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}, {"translation", {2, 3, 4}}});
  const GltfAsset a = read(b.gltf_bytes());
  ASSERT_EQ(a.cameras.size(), 1u);
  EXPECT_DOUBLE_EQ(a.cameras[0].yfov, 0.5);
  EXPECT_DOUBLE_EQ(a.cameras[0].aspect_ratio, 2.0);
  EXPECT_EQ(glm::dvec3(a.cameras[0].to_world[3]), glm::dvec3(0, 1, 5));
  ASSERT_EQ(a.lights.size(), 1u);
  EXPECT_EQ(a.lights[0].type, GltfLightType::kPoint);
  EXPECT_DOUBLE_EQ(a.lights[0].intensity, 8.0);
  EXPECT_EQ(glm::dvec3(a.lights[0].to_world[3]), glm::dvec3(2, 3, 4));
}

}  // namespace
}  // namespace penumbra::test
