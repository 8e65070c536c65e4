#pragma once
// Building small glTF 2.0 assets in tests: a JSON document and one binary buffer, written as a
// .gltf (buffer as a base64 data URI or a file) or as a .glb.
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace penumbra::test {

inline std::string base64(const std::vector<uint8_t>& data) {
  static const char* k = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  for (size_t i = 0; i < data.size(); i += 3) {
    const uint32_t n = uint32_t(data[i]) << 16 | (i + 1 < data.size() ? uint32_t(data[i + 1]) << 8 : 0) |
                       (i + 2 < data.size() ? data[i + 2] : 0);
    out += k[n >> 18 & 63];
    out += k[n >> 12 & 63];
    out += i + 1 < data.size() ? k[n >> 6 & 63] : '=';
    out += i + 2 < data.size() ? k[n & 63] : '=';
  }
  return out;
}

class GltfBuilder {
 public:
  using json = nlohmann::json;
  json doc = {{"asset", {{"version", "2.0"}}},
              {"buffers", json::array()},
              {"bufferViews", json::array()},
              {"accessors", json::array()},
              {"meshes", json::array()},
              {"nodes", json::array()},
              {"scenes", json::array({{{"nodes", json::array()}}})},
              {"scene", 0}};
  std::vector<uint8_t> bin;

  // Appends raw bytes (4-byte aligned) as a buffer view; returns its index.
  int view(const void* data, size_t bytes) {
    while (bin.size() % 4) bin.push_back(0);
    const size_t offset = bin.size();
    bin.insert(bin.end(), static_cast<const uint8_t*>(data), static_cast<const uint8_t*>(data) + bytes);
    doc["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", offset}, {"byteLength", bytes}});
    return int(doc["bufferViews"].size()) - 1;
  }
  int floats(const std::vector<float>& v, const char* type, int count) {
    const int bv = view(v.data(), v.size() * 4);
    doc["accessors"].push_back({{"bufferView", bv}, {"componentType", 5126}, {"count", count}, {"type", type}});
    return int(doc["accessors"].size()) - 1;
  }
  int indices(const std::vector<uint32_t>& v) {
    const int bv = view(v.data(), v.size() * 4);
    doc["accessors"].push_back({{"bufferView", bv}, {"componentType", 5125}, {"count", v.size()}, {"type", "SCALAR"}});
    return int(doc["accessors"].size()) - 1;
  }
  // A mesh of one primitive; returns the mesh index.
  int mesh(const std::vector<float>& positions, const std::vector<uint32_t>& idx, int material = -1,
           const std::vector<float>& uvs = {}) {
    json attributes = {{"POSITION", floats(positions, "VEC3", int(positions.size() / 3))}};
    if (!uvs.empty()) attributes["TEXCOORD_0"] = floats(uvs, "VEC2", int(uvs.size() / 2));
    json prim = {{"attributes", attributes}, {"indices", indices(idx)}};
    if (material >= 0) prim["material"] = material;
    doc["meshes"].push_back({{"primitives", json::array({prim})}});
    return int(doc["meshes"].size()) - 1;
  }
  // A node; `root` adds it to the scene.
  int node(json n, bool root = true) {
    doc["nodes"].push_back(std::move(n));
    const int i = int(doc["nodes"].size()) - 1;
    if (root) doc["scenes"][0]["nodes"].push_back(i);
    return i;
  }
  // The unit right triangle in the xy plane, as a mesh.
  int triangle(int material = -1) {
    return mesh({0, 0, 0, 1, 0, 0, 0, 1, 0}, {0, 1, 2}, material, {0, 0, 1, 0, 0, 1});
  }

  // .gltf text with the buffer as a data URI (or, given a name, as that file's URI).
  std::string gltf(const std::string& buffer_uri = "") const {
    json d = doc;
    if (bin.empty()) return d.dump();  // no buffer at all (an empty data URI is invalid)
    d["buffers"] = json::array({{{"byteLength", bin.size()},
                                 {"uri", buffer_uri.empty()
                                             ? "data:application/octet-stream;base64," + base64(bin)
                                             : buffer_uri}}});
    return d.dump();
  }
  std::vector<uint8_t> gltf_bytes(const std::string& buffer_uri = "") const {
    const std::string s = gltf(buffer_uri);
    return std::vector<uint8_t>(s.begin(), s.end());
  }
  // .glb: header, JSON chunk, BIN chunk (glTF 2.0 section 4.4).
  std::vector<uint8_t> glb() const {
    json d = doc;
    std::vector<uint8_t> b = bin;
    while (b.size() % 4) b.push_back(0);
    d["buffers"] = json::array({{{"byteLength", bin.size()}}});
    std::string text = d.dump();
    while (text.size() % 4) text += ' ';
    std::vector<uint8_t> out;
    auto u32 = [&](uint32_t v) {
      for (int i = 0; i < 4; ++i) out.push_back(uint8_t(v >> (8 * i)));
    };
    out.insert(out.end(), {'g', 'l', 'T', 'F'});
    u32(2);
    u32(uint32_t(12 + 8 + text.size() + 8 + b.size()));
    u32(uint32_t(text.size()));
    u32(0x4E4F534Au);
    out.insert(out.end(), text.begin(), text.end());
    u32(uint32_t(b.size()));
    u32(0x004E4942u);
    out.insert(out.end(), b.begin(), b.end());
    return out;
  }
};

}  // namespace penumbra::test
