#include "renderer/io/gltf_file.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <map>
#include <set>

#include <glm/gtc/quaternion.hpp>

#include "renderer/io/tiny_gltf_config.h"

namespace penumbra {
namespace {

[[noreturn]] void fail(const std::string& name, const std::string& reason) {
  throw GltfError(name + ": " + reason);
}

// ---- checks before tinygltf sees the bytes -------------------------------------------------

uint32_t read_u32(const uint8_t* p) {
  return uint32_t(p[0]) | uint32_t(p[1]) << 8 | uint32_t(p[2]) << 16 | uint32_t(p[3]) << 24;
}

// The GLB container (glTF 2.0 section 4.4): 12-byte header, a JSON chunk, an optional BIN
// chunk, every length inside the bytes present. Returns the JSON chunk.
std::pair<size_t, size_t> check_glb(const std::vector<uint8_t>& b, const std::string& name) {
  if (b.size() < 20) fail(name, "truncated GLB: " + std::to_string(b.size()) + " bytes");
  if (read_u32(&b[4]) != 2)
    fail(name, "GLB version " + std::to_string(read_u32(&b[4])) + "; only glTF 2.0 is read");
  const uint64_t length = read_u32(&b[8]);
  if (length > b.size())
    fail(name, "truncated GLB: its header announces " + std::to_string(length) +
                   " bytes, the file has " + std::to_string(b.size()));
  if (length < 20) fail(name, "GLB length " + std::to_string(length) + " is too small");
  const uint64_t json_length = read_u32(&b[12]);
  if (read_u32(&b[16]) != 0x4E4F534Au) fail(name, "the GLB's first chunk is not JSON");
  if (json_length == 0 || 20 + json_length > length)
    fail(name, "the GLB's JSON chunk (" + std::to_string(json_length) +
                   " bytes) does not fit in the file");
  uint64_t at = 20 + ((json_length + 3) & ~uint64_t(3));
  if (at + 8 <= length) {
    const uint64_t bin_length = read_u32(&b[at]);
    if (at + 8 + bin_length > length)
      fail(name, "the GLB's binary chunk (" + std::to_string(bin_length) +
                     " bytes) does not fit in the file");
  }
  return {20, size_t(json_length)};
}

// tinygltf turns "extras" and "extensions" into its Value tree recursively: cap the nesting
// depth of the JSON text before it parses it (strings skipped, escapes honoured).
void check_json_depth(const uint8_t* p, size_t n, int max_depth, const std::string& name) {
  int depth = 0;
  bool in_string = false;
  for (size_t i = 0; i < n; ++i) {
    const uint8_t c = p[i];
    if (in_string) {
      if (c == '\\') ++i;
      else if (c == '"') in_string = false;
      continue;
    }
    if (c == '"') in_string = true;
    else if (c == '{' || c == '[') {
      if (++depth > max_depth)
        fail(name, "the JSON is nested deeper than " + std::to_string(max_depth) + " levels");
    } else if (c == '}' || c == ']') {
      --depth;
    }
  }
}

// ---- tinygltf callbacks ----------------------------------------------------------------------

struct LoadContext {
  const std::string* name = nullptr;
  const GltfFileSource* files = nullptr;
  const GltfLimits* limits = nullptr;
  int64_t bytes_read = 0;
  std::string first_refusal;  // why a named file could not be read, naming it
  std::map<int, GltfImage> images;
};

std::string strip_dot_slash(std::string path) {
  while (path.rfind("./", 0) == 0) path.erase(0, 2);
  return path;
}

// Whether a file "exists" is left to ReadWholeFile, where a refusal can say why.
bool fs_file_exists(const std::string& path, void*) { return !path.empty(); }
// No expansion: tinygltf's default runs wordexp (the shell's ~ and $VAR) on URIs.
std::string fs_expand(const std::string& path, void*) { return path; }

bool fs_read(std::vector<unsigned char>* out, std::string* err, const std::string& path,
             void* user) {
  auto& ctx = *static_cast<LoadContext*>(user);
  const std::string uri = strip_dot_slash(path);
  std::string reason;
  std::vector<uint8_t> bytes;
  if (!(*ctx.files)(uri, &bytes, &reason)) {
    if (ctx.first_refusal.empty()) ctx.first_refusal = "'" + uri + "': " + reason;
    if (err) *err = reason;
    return false;
  }
  ctx.bytes_read += int64_t(bytes.size());
  if (ctx.bytes_read > ctx.limits->max_total_bytes) {
    if (ctx.first_refusal.empty())
      ctx.first_refusal = "the files it names exceed " +
                          std::to_string(ctx.limits->max_total_bytes) + " bytes together";
    if (err) *err = "too large";
    return false;
  }
  out->assign(bytes.begin(), bytes.end());
  return true;
}

bool fs_write(std::string* err, const std::string&, const std::vector<unsigned char>&, void*) {
  if (err) *err = "writing is not allowed";
  return false;
}

// Keeps the encoded bytes (decoded later by OpenImageIO, with its header checked against the
// texture limits first). glTF 2.0 allows PNG and JPEG; the magic bytes decide, not the URI.
bool keep_image(tinygltf::Image* image, const int index, std::string* err, std::string*, int,
                int, const unsigned char* bytes, int size, void* user) {
  auto& ctx = *static_cast<LoadContext*>(user);
  const std::string what = "images[" + std::to_string(index) + "]";
  if (int(ctx.images.size()) >= ctx.limits->max_images) {
    if (err) *err += what + ": more than " + std::to_string(ctx.limits->max_images) + " images\n";
    return false;
  }
  std::string extension;
  if (size >= 8 && std::memcmp(bytes, "\x89PNG\r\n\x1a\n", 8) == 0) extension = "png";
  else if (size >= 3 && bytes[0] == 0xFF && bytes[1] == 0xD8 && bytes[2] == 0xFF) extension = "jpg";
  if (extension.empty()) {
    if (err) *err += what + ": not a PNG or JPEG image (the formats glTF 2.0 allows)\n";
    return false;
  }
  GltfImage out;
  out.name = *ctx.name + ": " + what + (image->uri.empty() || image->uri.rfind("data:", 0) == 0
                                            ? std::string()
                                            : " ('" + image->uri + "')");
  out.bytes = std::make_shared<const std::vector<uint8_t>>(bytes, bytes + size);
  out.extension = extension;
  ctx.images[index] = std::move(out);
  image->width = image->height = 0;
  return true;
}

// ---- accessors -------------------------------------------------------------------------------

int component_bytes(int type) {
  switch (type) {
    case TINYGLTF_COMPONENT_TYPE_BYTE:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return 1;
    case TINYGLTF_COMPONENT_TYPE_SHORT:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: return 2;
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
    case TINYGLTF_COMPONENT_TYPE_FLOAT: return 4;
    default: return 0;
  }
}

int type_components(int type) {
  switch (type) {
    case TINYGLTF_TYPE_SCALAR: return 1;
    case TINYGLTF_TYPE_VEC2: return 2;
    case TINYGLTF_TYPE_VEC3: return 3;
    case TINYGLTF_TYPE_VEC4: return 4;
    default: return 0;
  }
}

// One component as a double: floats as stored, normalised integers mapped to [0, 1] or
// [-1, 1] (glTF 2.0 section 3.11), other integers as their value.
double component(const uint8_t* p, int type, bool normalized) {
  switch (type) {
    case TINYGLTF_COMPONENT_TYPE_FLOAT: {
      float f;
      std::memcpy(&f, p, 4);
      return f;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return normalized ? p[0] / 255.0 : p[0];
    case TINYGLTF_COMPONENT_TYPE_BYTE: {
      const auto v = int8_t(p[0]);
      return normalized ? std::max(v / 127.0, -1.0) : v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
      uint16_t v;
      std::memcpy(&v, p, 2);
      return normalized ? v / 65535.0 : v;
    }
    case TINYGLTF_COMPONENT_TYPE_SHORT: {
      int16_t v;
      std::memcpy(&v, p, 2);
      return normalized ? std::max(v / 32767.0, -1.0) : v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: {
      uint32_t v;
      std::memcpy(&v, p, 4);
      return v;
    }
    default: return 0.0;
  }
}

class AccessorReader {
 public:
  AccessorReader(const tinygltf::Model& model, const std::string& name)
      : model_(model), name_(name) {}

  // The bytes of `count` elements of `element_bytes` each, `stride` apart, from buffer view
  // `view` at `offset`: checked to lie inside the view and the view inside its buffer.
  const uint8_t* span(int view, uint64_t offset, uint64_t count, uint64_t element_bytes,
                      uint64_t* stride, const std::string& what) const {
    if (view < 0 || size_t(view) >= model_.bufferViews.size())
      fail(name_, what + ": buffer view " + std::to_string(view) + " does not exist");
    const tinygltf::BufferView& bv = model_.bufferViews[size_t(view)];
    if (bv.buffer < 0 || size_t(bv.buffer) >= model_.buffers.size())
      fail(name_, what + ": buffer " + std::to_string(bv.buffer) + " does not exist");
    const auto& data = model_.buffers[size_t(bv.buffer)].data;
    if (bv.byteOffset > data.size() || bv.byteLength > data.size() - bv.byteOffset)
      fail(name_, what + ": bufferViews[" + std::to_string(view) + "] (" +
                      std::to_string(bv.byteLength) + " bytes at " + std::to_string(bv.byteOffset) +
                      ") lies outside its buffer of " + std::to_string(data.size()) + " bytes");
    if (*stride == 0) *stride = bv.byteStride != 0 ? bv.byteStride : element_bytes;
    if (*stride < element_bytes)
      fail(name_, what + ": byte stride " + std::to_string(*stride) + " is smaller than an element (" +
                      std::to_string(element_bytes) + " bytes)");
    // count <= 2^32 and stride <= 2^32 (checked by the callers): no overflow in 64 bits.
    const uint64_t needed = count == 0 ? 0 : offset + *stride * (count - 1) + element_bytes;
    if (offset > bv.byteLength || needed > bv.byteLength)
      fail(name_, what + ": " + std::to_string(count) + " elements need " + std::to_string(needed) +
                      " bytes of a buffer view of " + std::to_string(bv.byteLength));
    return data.data() + bv.byteOffset;
  }

  // Accessor `index` as `components`-wide doubles (sparse substitution applied), checked to have
  // that width and at most `max_count` elements.
  std::vector<double> read(int index, int components, uint64_t max_count,
                           const std::string& what) const {
    if (index < 0 || size_t(index) >= model_.accessors.size())
      fail(name_, what + ": accessor " + std::to_string(index) + " does not exist");
    const tinygltf::Accessor& a = model_.accessors[size_t(index)];
    const std::string where = what + " (accessors[" + std::to_string(index) + "])";
    const int width = type_components(a.type);
    const int cbytes = component_bytes(a.componentType);
    if (width != components || cbytes == 0)
      fail(name_, where + ": expected " + std::to_string(components) + " components per element");
    if (a.count > max_count)
      fail(name_, where + ": " + std::to_string(a.count) + " elements, more than the limit of " +
                      std::to_string(max_count));
    std::vector<double> out(size_t(a.count) * size_t(width), 0.0);
    if (a.bufferView >= 0) {
      uint64_t stride = 0;
      const uint8_t* base =
          span(a.bufferView, a.byteOffset, a.count, uint64_t(width) * cbytes, &stride, where);
      for (size_t i = 0; i < a.count; ++i)
        for (int c = 0; c < width; ++c)
          out[i * size_t(width) + size_t(c)] =
              component(base + a.byteOffset + i * stride + size_t(c) * size_t(cbytes),
                        a.componentType, a.normalized);
    }
    if (a.sparse.isSparse) apply_sparse(a, width, cbytes, out, where);
    for (double v : out)
      if (!std::isfinite(v) || std::abs(v) > double(std::numeric_limits<float>::max()))
        fail(name_, where + ": holds a value that is not a finite single-precision number");
    return out;
  }

  // Indices: unsigned integers, each < vertex_count.
  std::vector<uint32_t> indices(int index, uint64_t vertex_count, uint64_t max_count,
                                const std::string& what) const {
    if (index < 0 || size_t(index) >= model_.accessors.size())
      fail(name_, what + ": accessor " + std::to_string(index) + " does not exist");
    const tinygltf::Accessor& a = model_.accessors[size_t(index)];
    if (a.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE &&
        a.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
        a.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT)
      fail(name_, what + ": indices must be unsigned integers");
    const std::vector<double> values = read(index, 1, max_count, what);
    std::vector<uint32_t> out(values.size());
    for (size_t i = 0; i < values.size(); ++i) {
      if (!(values[i] >= 0 && values[i] < double(vertex_count)))
        fail(name_, what + ": index " + std::to_string(uint64_t(values[i])) + " at position " +
                        std::to_string(i) + " is out of range: there are " +
                        std::to_string(vertex_count) + " vertices");
      out[i] = uint32_t(values[i]);
    }
    return out;
  }

 private:
  void apply_sparse(const tinygltf::Accessor& a, int width, int cbytes, std::vector<double>& out,
                    const std::string& where) const {
    const uint64_t n = uint64_t(std::max(a.sparse.count, 0));
    if (n > a.count) fail(name_, where + ": more sparse substitutions than elements");
    const int itype = a.sparse.indices.componentType;
    const int ibytes = component_bytes(itype);
    if (ibytes == 0 || itype == TINYGLTF_COMPONENT_TYPE_FLOAT || itype == TINYGLTF_COMPONENT_TYPE_BYTE ||
        itype == TINYGLTF_COMPONENT_TYPE_SHORT)
      fail(name_, where + ": sparse indices must be unsigned integers");
    uint64_t istride = uint64_t(ibytes), vstride = uint64_t(width) * cbytes;
    const uint8_t* ib = span(a.sparse.indices.bufferView, uint64_t(std::max(a.sparse.indices.byteOffset, 0)),
                             n, uint64_t(ibytes), &istride, where + " sparse indices");
    const uint8_t* vb = span(a.sparse.values.bufferView, uint64_t(std::max(a.sparse.values.byteOffset, 0)),
                             n, vstride, &vstride, where + " sparse values");
    ib += std::max(a.sparse.indices.byteOffset, 0);
    vb += std::max(a.sparse.values.byteOffset, 0);
    for (uint64_t k = 0; k < n; ++k) {
      const double target = component(ib + k * istride, itype, false);
      if (!(target < double(a.count))) fail(name_, where + ": a sparse index is out of range");
      for (int c = 0; c < width; ++c)
        out[size_t(target) * size_t(width) + size_t(c)] =
            component(vb + k * vstride + size_t(c) * size_t(cbytes), a.componentType, a.normalized);
    }
  }

  const tinygltf::Model& model_;
  const std::string& name_;
};

// ---- conversion ------------------------------------------------------------------------------

bool finite_all(const std::vector<double>& v) {
  return std::all_of(v.begin(), v.end(), [](double x) { return std::isfinite(x); });
}

glm::dmat4 local_matrix(const tinygltf::Node& node, const std::string& name,
                        const std::string& what) {
  if (!finite_all(node.matrix) || !finite_all(node.translation) || !finite_all(node.rotation) ||
      !finite_all(node.scale))
    fail(name, what + ": its transform holds a non-finite number");
  if (node.matrix.size() == 16) {
    glm::dmat4 m;
    for (int c = 0; c < 4; ++c)
      for (int r = 0; r < 4; ++r) m[c][r] = node.matrix[size_t(4 * c + r)];  // column-major
    return m;
  }
  glm::dmat4 t(1.0), r(1.0), s(1.0);
  if (node.translation.size() == 3)
    t = glm::translate(glm::dmat4(1.0), glm::dvec3(node.translation[0], node.translation[1],
                                                   node.translation[2]));
  if (node.rotation.size() == 4) {
    // glTF stores (x, y, z, w); glm's constructor takes (w, x, y, z).
    glm::dquat q(node.rotation[3], node.rotation[0], node.rotation[1], node.rotation[2]);
    const double len = glm::length(q);
    if (!(len > 0)) fail(name, what + ": its rotation quaternion is zero");
    r = glm::mat4_cast(q / len);
  }
  if (node.scale.size() == 3)
    s = glm::scale(glm::dmat4(1.0), glm::dvec3(node.scale[0], node.scale[1], node.scale[2]));
  return t * r * s;
}

Spectrum factor3(const std::vector<double>& v, Spectrum fallback, const std::string& name,
                 const std::string& what) {
  if (v.empty()) return fallback;
  if (v.size() < 3 || !finite_all(v)) fail(name, what + " must hold finite numbers");
  return Spectrum(float(v[0]), float(v[1]), float(v[2]));
}

float unit_factor(double v, const std::string& name, const std::string& what) {
  if (!std::isfinite(v)) fail(name, what + " must be a finite number");
  return float(std::clamp(v, 0.0, 1.0));
}

// The extensions this reader understands: a file requiring another is refused, one merely
// using another renders without it (with a warning).
const std::set<std::string>& supported_extensions() {
  static const std::set<std::string> s = {"KHR_lights_punctual", "KHR_materials_emissive_strength",
                                          "KHR_mesh_quantization"};
  return s;
}

class Converter {
 public:
  Converter(const tinygltf::Model& model, const std::string& name, const GltfLimits& limits,
            GltfAsset& out)
      : m_(model), name_(name), limits_(limits), out_(out), accessors_(model, name) {}

  void run(std::map<int, GltfImage>& images) {
    check_extensions();
    images_.assign(m_.images.size(), -1);
    for (auto& [index, image] : images) {
      if (index < 0 || size_t(index) >= m_.images.size()) continue;
      images_[size_t(index)] = int(out_.images.size());
      out_.images.push_back(std::move(image));
    }
    for (size_t i = 0; i < m_.materials.size(); ++i) out_.materials.push_back(material(i));
    meshes();
    hierarchy();
  }

 private:
  void warn(const std::string& text) {
    if (std::find(out_.warnings.begin(), out_.warnings.end(), text) == out_.warnings.end())
      out_.warnings.push_back(text);
  }

  void check_extensions() {
    for (const std::string& e : m_.extensionsRequired)
      if (!supported_extensions().count(e))
        fail(name_, "requires the extension " + e + ", which penumbra does not support (it reads " +
                        "KHR_lights_punctual, KHR_materials_emissive_strength and " +
                        "KHR_mesh_quantization)");
    for (const std::string& e : m_.extensionsUsed)
      if (!supported_extensions().count(e))
        warn("uses the optional extension " + e + ", which penumbra ignores");
  }

  std::optional<GltfTextureRef> texture(int index, int tex_coord, const std::string& what) {
    if (index < 0) return std::nullopt;
    if (size_t(index) >= m_.textures.size())
      fail(name_, what + ": texture " + std::to_string(index) + " does not exist");
    if (tex_coord != 0)
      warn(what + " reads TEXCOORD_" + std::to_string(tex_coord) +
           "; penumbra reads TEXCOORD_0 for every texture");
    const tinygltf::Texture& t = m_.textures[size_t(index)];
    if (t.source < 0 || size_t(t.source) >= m_.images.size()) {
      warn(what + ": textures[" + std::to_string(index) +
           "] has no image penumbra can read (only an extension's source?); ignored");
      return std::nullopt;
    }
    if (images_[size_t(t.source)] < 0)
      fail(name_, what + ": images[" + std::to_string(t.source) + "] could not be read");
    GltfTextureRef ref;
    ref.image = images_[size_t(t.source)];
    if (t.sampler >= 0) {
      if (size_t(t.sampler) >= m_.samplers.size())
        fail(name_, what + ": sampler " + std::to_string(t.sampler) + " does not exist");
      const tinygltf::Sampler& s = m_.samplers[size_t(t.sampler)];
      const bool clamp_s = s.wrapS == TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE;
      const bool clamp_t = s.wrapT == TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE;
      if (clamp_s != clamp_t || s.wrapS == TINYGLTF_TEXTURE_WRAP_MIRRORED_REPEAT ||
          s.wrapT == TINYGLTF_TEXTURE_WRAP_MIRRORED_REPEAT)
        warn("samplers[" + std::to_string(t.sampler) +
             "]: mirrored or per-axis wrap modes are read as " +
             (clamp_s && clamp_t ? "clamp" : "repeat") + " on both axes");
      ref.wrap = clamp_s && clamp_t ? TextureWrap::kClamp : TextureWrap::kRepeat;
      ref.filter = s.magFilter == TINYGLTF_TEXTURE_FILTER_NEAREST ? TextureFilter::kNearest
                                                                  : TextureFilter::kBilinear;
    }
    return ref;
  }

  GltfMaterial material(size_t i) {
    const tinygltf::Material& src = m_.materials[i];
    const std::string what = "materials[" + std::to_string(i) + "]";
    GltfMaterial mat;
    mat.name = src.name;
    const auto& pbr = src.pbrMetallicRoughness;
    if (!pbr.baseColorFactor.empty()) {
      if (pbr.baseColorFactor.size() != 4 || !finite_all(pbr.baseColorFactor))
        fail(name_, what + ": baseColorFactor must hold 4 finite numbers");
      mat.base_color = glm::clamp(factor3(pbr.baseColorFactor, Spectrum(1.f), name_, what),
                                  Spectrum(0.f), Spectrum(1.f));
      mat.alpha = unit_factor(pbr.baseColorFactor[3], name_, what + ": baseColorFactor");
    }
    mat.metallic = unit_factor(pbr.metallicFactor, name_, what + ": metallicFactor");
    mat.roughness = unit_factor(pbr.roughnessFactor, name_, what + ": roughnessFactor");
    mat.base_color_texture = texture(pbr.baseColorTexture.index, pbr.baseColorTexture.texCoord,
                                     what + ".baseColorTexture");
    mat.metallic_roughness_texture =
        texture(pbr.metallicRoughnessTexture.index, pbr.metallicRoughnessTexture.texCoord,
                what + ".metallicRoughnessTexture");
    mat.normal_texture =
        texture(src.normalTexture.index, src.normalTexture.texCoord, what + ".normalTexture");
    if (mat.normal_texture) {
      if (!std::isfinite(src.normalTexture.scale))
        fail(name_, what + ": normalTexture.scale must be finite");
      mat.normal_texture->scale = float(src.normalTexture.scale);
    }
    mat.emissive_texture =
        texture(src.emissiveTexture.index, src.emissiveTexture.texCoord, what + ".emissiveTexture");
    Spectrum emissive = factor3(src.emissiveFactor, Spectrum(0.f), name_, what + ": emissiveFactor");
    emissive = glm::clamp(emissive, Spectrum(0.f), Spectrum(1.f));
    if (auto it = src.extensions.find("KHR_materials_emissive_strength"); it != src.extensions.end()) {
      const tinygltf::Value& v = it->second;
      if (v.IsObject() && v.Has("emissiveStrength")) {
        const tinygltf::Value& s = v.Get("emissiveStrength");
        const double strength = s.IsNumber() ? s.GetNumberAsDouble() : -1.0;
        if (!(strength >= 0) || !(strength <= 1e30))
          fail(name_, what + ": emissiveStrength must be a finite number >= 0");
        emissive *= float(strength);
      }
    }
    mat.emissive = emissive;
    if (src.occlusionTexture.index >= 0)
      warn(what + ": occlusionTexture is ignored (a path tracer computes occlusion)");
    if (src.alphaMode == "MASK") mat.alpha_mode = GltfAlphaMode::kMask;
    else if (src.alphaMode == "BLEND") mat.alpha_mode = GltfAlphaMode::kBlend;
    else if (src.alphaMode != "OPAQUE" && !src.alphaMode.empty())
      fail(name_, what + ": unknown alphaMode '" + src.alphaMode + "'");
    if (!std::isfinite(src.alphaCutoff) || src.alphaCutoff < 0)
      fail(name_, what + ": alphaCutoff must be a finite number >= 0");
    mat.alpha_cutoff = float(src.alphaCutoff);
    mat.double_sided = src.doubleSided;
    return mat;
  }

  void meshes() {
    int64_t vertices = 0, triangles = 0;
    for (size_t i = 0; i < m_.meshes.size(); ++i) {
      const tinygltf::Mesh& src = m_.meshes[i];
      GltfMesh mesh;
      mesh.name = src.name;
      for (size_t p = 0; p < src.primitives.size(); ++p) {
        const std::string what =
            "meshes[" + std::to_string(i) + "].primitives[" + std::to_string(p) + "]";
        if (auto prim = primitive(src.primitives[p], what, vertices, triangles))
          mesh.primitives.push_back(std::move(*prim));
      }
      out_.meshes.push_back(std::move(mesh));
    }
  }

  std::optional<GltfPrimitive> primitive(const tinygltf::Primitive& src, const std::string& what,
                                         int64_t& vertices, int64_t& triangles) {
    const int mode = src.mode < 0 ? TINYGLTF_MODE_TRIANGLES : src.mode;
    if (mode != TINYGLTF_MODE_TRIANGLES && mode != TINYGLTF_MODE_TRIANGLE_STRIP &&
        mode != TINYGLTF_MODE_TRIANGLE_FAN) {
      warn(what + ": points and lines are not rendered");
      return std::nullopt;
    }
    if (!src.targets.empty()) warn(what + ": morph targets are ignored (the base shape is rendered)");
    const auto pos = src.attributes.find("POSITION");
    if (pos == src.attributes.end()) fail(name_, what + ": has no POSITION attribute");
    if (src.material >= 0 && size_t(src.material) >= m_.materials.size())
      fail(name_, what + ": material " + std::to_string(src.material) + " does not exist");
    const uint64_t vertex_room = uint64_t(std::max<int64_t>(limits_.max_vertices - vertices, 0));
    GltfPrimitive prim;
    prim.material = src.material;
    const std::vector<double> p = accessors_.read(pos->second, 3, vertex_room, what + ".POSITION");
    const size_t n = p.size() / 3;
    prim.positions.resize(n);
    for (size_t v = 0; v < n; ++v)
      prim.positions[v] = vec3(float(p[3 * v]), float(p[3 * v + 1]), float(p[3 * v + 2]));
    if (auto it = src.attributes.find("NORMAL"); it != src.attributes.end()) {
      const std::vector<double> q = accessors_.read(it->second, 3, n, what + ".NORMAL");
      if (q.size() != p.size()) fail(name_, what + ": NORMAL and POSITION differ in count");
      prim.normals.resize(n);
      for (size_t v = 0; v < n; ++v)
        prim.normals[v] = vec3(float(q[3 * v]), float(q[3 * v + 1]), float(q[3 * v + 2]));
    }
    if (auto it = src.attributes.find("TEXCOORD_0"); it != src.attributes.end()) {
      const std::vector<double> q = accessors_.read(it->second, 2, n, what + ".TEXCOORD_0");
      if (q.size() != 2 * n) fail(name_, what + ": TEXCOORD_0 and POSITION differ in count");
      prim.uvs.resize(n);
      for (size_t v = 0; v < n; ++v) prim.uvs[v] = vec2(float(q[2 * v]), float(q[2 * v + 1]));
    }
    // Corner list of the mode, then triangles.
    const uint64_t corner_room = 3 * uint64_t(std::max<int64_t>(limits_.max_triangles - triangles, 0)) + 2;
    std::vector<uint32_t> corners;
    if (src.indices >= 0) {
      corners = accessors_.indices(src.indices, n, corner_room, what + ".indices");
    } else {
      if (n > corner_room) fail(name_, what + ": too many vertices for the triangle limit");
      corners.resize(n);
      for (size_t v = 0; v < n; ++v) corners[v] = uint32_t(v);
    }
    std::vector<uint32_t>& tri = prim.indices;
    if (mode == TINYGLTF_MODE_TRIANGLES) {
      if (corners.size() % 3 != 0)
        fail(name_, what + ": " + std::to_string(corners.size()) + " indices, not a multiple of 3");
      tri = std::move(corners);
    } else if (corners.size() >= 3) {
      tri.reserve(3 * (corners.size() - 2));
      for (size_t k = 2; k < corners.size(); ++k) {
        if (mode == TINYGLTF_MODE_TRIANGLE_FAN) {
          tri.insert(tri.end(), {corners[0], corners[k - 1], corners[k]});
        } else if (k % 2 == 0) {  // strips alternate their winding (glTF 2.0 section 3.7.2.1)
          tri.insert(tri.end(), {corners[k - 2], corners[k - 1], corners[k]});
        } else {
          tri.insert(tri.end(), {corners[k - 1], corners[k - 2], corners[k]});
        }
      }
    }
    if (tri.empty()) {
      warn(what + ": has no triangles");
      return std::nullopt;
    }
    vertices += int64_t(n);
    triangles += int64_t(tri.size() / 3);
    if (triangles > limits_.max_triangles)
      fail(name_, "more than " + std::to_string(limits_.max_triangles) + " triangles");
    return prim;
  }

  void hierarchy() {
    std::vector<int> roots;
    if (!m_.scenes.empty()) {
      int scene = m_.defaultScene;
      if (scene < 0) scene = 0;
      if (size_t(scene) >= m_.scenes.size())
        fail(name_, "scene " + std::to_string(scene) + " does not exist");
      roots = m_.scenes[size_t(scene)].nodes;
    } else {
      // No scene: every node that is nobody's child.
      std::vector<bool> child(m_.nodes.size(), false);
      for (const auto& node : m_.nodes)
        for (int c : node.children)
          if (c >= 0 && size_t(c) < child.size()) child[size_t(c)] = true;
      for (size_t i = 0; i < m_.nodes.size(); ++i)
        if (!child[i]) roots.push_back(int(i));
    }
    struct Item {
      int node;
      glm::dmat4 parent;
      int depth;
    };
    std::vector<Item> stack;
    for (auto it = roots.rbegin(); it != roots.rend(); ++it) stack.push_back({*it, glm::dmat4(1.0), 1});
    int visits = 0;
    std::vector<int> on_path_depth(m_.nodes.size(), 0);
    while (!stack.empty()) {
      const Item item = stack.back();
      stack.pop_back();
      if (item.node < 0 || size_t(item.node) >= m_.nodes.size())
        fail(name_, "node " + std::to_string(item.node) + " does not exist");
      if (++visits > limits_.max_nodes_visited)
        fail(name_, "the node hierarchy visits more than " +
                        std::to_string(limits_.max_nodes_visited) +
                        " nodes (a node with several parents, or a cycle?)");
      if (item.depth > limits_.max_depth)
        fail(name_, "the node hierarchy is deeper than " + std::to_string(limits_.max_depth) +
                        " levels (or has a cycle)");
      const tinygltf::Node& node = m_.nodes[size_t(item.node)];
      const std::string what = "nodes[" + std::to_string(item.node) + "]";
      const glm::dmat4 world = item.parent * local_matrix(node, name_, what);
      if (node.mesh >= 0) {
        if (size_t(node.mesh) >= m_.meshes.size())
          fail(name_, what + ": mesh " + std::to_string(node.mesh) + " does not exist");
        if (node.skin >= 0) warn(what + ": skinning is ignored (the mesh is rendered unposed)");
        out_.instances.push_back({node.mesh, item.node, world, node.name});
      }
      if (node.camera >= 0) camera(node, world, what);
      if (auto it = node.extensions.find("KHR_lights_punctual"); it != node.extensions.end())
        light(it->second, world, what);
      for (auto c = node.children.rbegin(); c != node.children.rend(); ++c)
        stack.push_back({*c, world, item.depth + 1});
    }
  }

  void camera(const tinygltf::Node& node, const glm::dmat4& world, const std::string& what) {
    if (size_t(node.camera) >= m_.cameras.size())
      fail(name_, what + ": camera " + std::to_string(node.camera) + " does not exist");
    const tinygltf::Camera& src = m_.cameras[size_t(node.camera)];
    GltfCamera cam;
    cam.name = src.name;
    cam.to_world = world;
    cam.perspective = src.type != "orthographic";
    if (cam.perspective) {
      cam.yfov = src.perspective.yfov;
      cam.aspect_ratio = src.perspective.aspectRatio;
      if (!(cam.yfov > 0 && cam.yfov < kPi))
        fail(name_, "cameras[" + std::to_string(node.camera) + "]: yfov must lie in (0, pi)");
      if (!std::isfinite(cam.aspect_ratio) || cam.aspect_ratio < 0) cam.aspect_ratio = 0;
    } else {
      cam.ymag = src.orthographic.ymag;
    }
    out_.cameras.push_back(cam);
  }

  void light(const tinygltf::Value& ext, const glm::dmat4& world, const std::string& what) {
    if (!ext.IsObject() || !ext.Has("light") || !ext.Get("light").IsNumber()) return;
    const int index = ext.Get("light").GetNumberAsInt();
    if (index < 0 || size_t(index) >= m_.lights.size())
      fail(name_, what + ": light " + std::to_string(index) + " does not exist");
    const tinygltf::Light& src = m_.lights[size_t(index)];
    const std::string lw = "KHR_lights_punctual lights[" + std::to_string(index) + "]";
    GltfLight l;
    l.name = src.name;
    l.to_world = world;
    if (src.type == "point") l.type = GltfLightType::kPoint;
    else if (src.type == "spot") l.type = GltfLightType::kSpot;
    else if (src.type == "directional") l.type = GltfLightType::kDirectional;
    else fail(name_, lw + ": unknown type '" + src.type + "'");
    l.color = glm::clamp(factor3(src.color, Spectrum(1.f), name_, lw + ": color"), Spectrum(0.f),
                         Spectrum(1.f));
    if (!(src.intensity >= 0) || !(src.intensity <= 1e30))
      fail(name_, lw + ": intensity must be a finite number >= 0");
    l.intensity = src.intensity;
    l.range = std::isfinite(src.range) ? src.range : 0.0;
    l.inner_cone = src.spot.innerConeAngle;
    l.outer_cone = src.spot.outerConeAngle;
    if (l.type == GltfLightType::kSpot &&
        !(l.inner_cone >= 0 && l.inner_cone < l.outer_cone && l.outer_cone <= kPi / 2))
      fail(name_, lw + ": needs 0 <= innerConeAngle < outerConeAngle <= pi/2");
    out_.lights.push_back(l);
  }

  const tinygltf::Model& m_;
  const std::string& name_;
  const GltfLimits& limits_;
  GltfAsset& out_;
  AccessorReader accessors_;
  std::vector<int> images_;  // glTF image index -> GltfAsset::images index, -1 if unread
};

}  // namespace

bool is_gltf_file_name(const std::string& path) {
  const auto dot = path.find_last_of('.');
  if (dot == std::string::npos) return false;
  std::string ext = path.substr(dot + 1);
  for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  return ext == "gltf" || ext == "glb";
}

GltfAsset read_gltf(const std::vector<uint8_t>& bytes, const std::string& name,
                    const GltfFileSource& files, const GltfLimits& limits) {
  if (int64_t(bytes.size()) > limits.max_file_bytes)
    fail(name, "the file has " + std::to_string(bytes.size()) + " bytes; at most " +
                   std::to_string(limits.max_file_bytes));
  if (bytes.size() > std::numeric_limits<unsigned int>::max()) fail(name, "the file is too large");
  const bool binary = bytes.size() >= 4 && std::memcmp(bytes.data(), "glTF", 4) == 0;
  if (binary) {
    const auto [offset, length] = check_glb(bytes, name);
    check_json_depth(bytes.data() + offset, length, limits.max_depth, name);
  } else {
    check_json_depth(bytes.data(), bytes.size(), limits.max_depth, name);
  }

  LoadContext ctx;
  ctx.name = &name;
  ctx.files = &files;
  ctx.limits = &limits;
  ctx.bytes_read = int64_t(bytes.size());
  tinygltf::TinyGLTF loader;
  loader.SetImageLoader(keep_image, &ctx);
  loader.SetFsCallbacks({fs_file_exists, fs_expand, fs_read, fs_write, &ctx});
  tinygltf::Model model;
  std::string err, warn;
  bool ok = false;
  try {
    ok = binary ? loader.LoadBinaryFromMemory(&model, &err, &warn, bytes.data(),
                                              unsigned(bytes.size()), "")
                : loader.LoadASCIIFromString(&model, &err, &warn,
                                             reinterpret_cast<const char*>(bytes.data()),
                                             unsigned(bytes.size()), "");
  } catch (const std::bad_alloc&) {
    fail(name, "out of memory while parsing");
  } catch (const std::exception& e) {
    fail(name, std::string("cannot be parsed: ") + e.what());
  }
  // A file the asset names that could not be read comes back from tinygltf as a warning with
  // ok == true (images) or as an error: either way it is an error here, naming the file.
  if (!ctx.first_refusal.empty()) fail(name, "cannot read " + ctx.first_refusal);
  auto trim = [](std::string s) {
    while (!s.empty() && (s.back() == '\n' || s.back() == ' ')) s.pop_back();
    for (char& c : s)
      if (c == '\n') c = ';';
    return s;
  };
  if (!ok) fail(name, trim(err.empty() ? "cannot be parsed" : err));
  if (!warn.empty()) fail(name, trim(warn));

  GltfAsset asset;
  asset.file_bytes = ctx.bytes_read;
  try {
    Converter(model, name, limits, asset).run(ctx.images);
  } catch (const std::bad_alloc&) {
    fail(name, "out of memory while reading");
  }
  return asset;
}

}  // namespace penumbra
