// libFuzzer target: arbitrary bytes through the glTF reader (renderer/io/gltf_file.h), as .glb
// or .gltf JSON, with tinygltf underneath. Malformed input must give a GltfError naming the
// file, never a crash, hang, leak, undefined behaviour or an allocation beyond the limits (the
// build adds ASan and UBSan; scripts/fuzz.sh caps memory). Files the input names are served
// only for "b.bin" (the input's own bytes again, so buffers and images get fuzzed too); every
// other URI is refused, as the asset folder would. An asset that is read must be consistent.
#include <cstdlib>

#include "renderer/io/gltf_file.h"

namespace {

void require(bool ok) {
  if (!ok) std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace penumbra;
  const std::vector<uint8_t> bytes(data, data + size);
  const GltfFileSource files = [&](const std::string& uri, std::vector<uint8_t>* out,
                                   std::string* why) {
    if (uri == "b.bin") {
      *out = bytes;
      return true;
    }
    *why = "not in the fuzz folder";
    return false;
  };
  GltfLimits limits;
  limits.max_vertices = 1 << 16;
  limits.max_triangles = 1 << 16;
  limits.max_nodes_visited = 1 << 12;
  limits.max_total_bytes = 1 << 24;
  try {
    const GltfAsset asset = read_gltf(bytes, "'fuzz.glb'", files, limits);
    for (const GltfMesh& mesh : asset.meshes)
      for (const GltfPrimitive& p : mesh.primitives) {
        require(p.indices.size() % 3 == 0 && !p.indices.empty());
        for (uint32_t i : p.indices) require(i < p.positions.size());
        require(p.normals.empty() || p.normals.size() == p.positions.size());
        require(p.uvs.empty() || p.uvs.size() == p.positions.size());
        require(p.material < int(asset.materials.size()));
        for (const vec3& v : p.positions) require(is_finite(v));
      }
    for (const GltfMeshInstance& inst : asset.instances)
      require(inst.mesh >= 0 && size_t(inst.mesh) < asset.meshes.size());
    for (const GltfMaterial& m : asset.materials)
      for (const auto* t : {&m.base_color_texture, &m.metallic_roughness_texture, &m.normal_texture,
                            &m.emissive_texture})
        if (*t) require((*t)->image >= 0 && size_t((*t)->image) < asset.images.size());
  } catch (const GltfError&) {
  }
  return 0;
}
