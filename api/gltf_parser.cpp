#include "api/gltf_parser.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <new>

#include "api/diagnostics.h"
#include "renderer/io/file_bytes.h"

namespace penumbra::api {
namespace {

namespace fs = std::filesystem;

// Reads at most max_bytes (the size is checked before anything is mapped or allocated), through
// the mesh readers' FileBytes: the same messages, and a file that shrinks meanwhile is an error.
bool read_capped(const fs::path& path, int64_t max_bytes, std::vector<uint8_t>* out,
                 std::string* reason) {
  try {
    const FileBytes file = FileBytes::map(path, max_bytes);
    const std::string_view bytes = file.view();
    out->assign(bytes.begin(), bytes.end());
    if (!file.intact()) {
      *reason = "the file changed while it was read (or a part of it could not be read)";
      return false;
    }
    return true;
  } catch (const FileBytesError& e) {
    *reason = e.what();
    return false;
  }
}

vec3 to_float(const glm::dvec3& v) { return vec3(float(v.x), float(v.y), float(v.z)); }

AffineTransform affine(const glm::dmat4& m) {
  AffineTransform t;
  t.linear = glm::dmat3(m);
  t.translation = glm::dvec3(m[3]);
  return t;
}

// The glTF images a scene's materials use, each probed once (header only) as a texture.
class GltfTextures {
 public:
  GltfTextures(const GltfAsset& asset, const std::string& file, const std::string& pointer,
               TextureSet& textures, Diagnostics& diag)
      : asset_(asset), file_(file), pointer_(pointer), textures_(textures), diag_(diag) {}

  // The texture of `ref` read as `colorspace`, channel `channel`; nullopt (with an error) when
  // its image cannot be used.
  std::optional<ImageTextureDesc> get(const GltfTextureRef& ref, TextureColorspace colorspace,
                                      int channel = 0) {
    const GltfImage& image = asset_.images[size_t(ref.image)];
    // One key per image of this file: images shared by materials (or by two objects placing
    // the same file) are decoded once.
    const std::string key = file_ + "#images/" + std::to_string(ref.image);
    ImageTextureDesc desc;
    desc.path = key;
    desc.name = image.name;
    desc.bytes = image.bytes;
    desc.format = image.extension;
    desc.colorspace = colorspace;
    desc.channel = channel;
    desc.wrap = ref.wrap;
    desc.filter = ref.filter;
    const auto info = textures_.probe_memory(key, desc.source(), pointer_, diag_);
    if (!info) return std::nullopt;
    if (channel >= info->channels) {
      diag_.error(pointer_, image.name + ": has " + std::to_string(info->channels) +
                                " channel(s); channel " + std::to_string(channel) +
                                " is needed");
      return std::nullopt;
    }
    if (!textures_.reserve(key, colorspace, *info, pointer_, diag_)) return std::nullopt;
    return desc;
  }

  // Channels of the texture's image (0 when it cannot be read: get() reports why).
  int channels(const GltfTextureRef& ref) {
    const GltfImage& image = asset_.images[size_t(ref.image)];
    const std::string key = file_ + "#images/" + std::to_string(ref.image);
    ImageTextureDesc desc;
    desc.path = key;
    desc.name = image.name;
    desc.bytes = image.bytes;
    desc.format = image.extension;
    const auto info = textures_.probe_memory(key, desc.source(), pointer_, diag_);
    return info ? info->channels : 0;
  }

 private:
  const GltfAsset& asset_;
  const std::string& file_;
  const std::string& pointer_;
  TextureSet& textures_;
  Diagnostics& diag_;
};

struct MaterialAndEmission {
  MetallicRoughnessParams params;
  Spectrum emission{0.f};
  std::optional<ImageTextureDesc> emission_texture;
  // alphaMode MASK: the cutout (base colour texture's alpha x factor against the cutoff), or,
  // without an alpha channel, the whole surface kept or (`hidden`) left out.
  std::optional<ImageTextureDesc> alpha_texture;
  float alpha_factor = 1.f;
  float alpha_cutoff = 0.5f;
  bool hidden = false;
};

MaterialAndEmission convert_material(const GltfMaterial& m, GltfTextures& textures,
                                     Diagnostics& diag, const std::string& pointer,
                                     const std::string& label) {
  MaterialAndEmission out;
  MetallicRoughnessParams& p = out.params;
  p.color = m.base_color;
  p.metallic = m.metallic;
  p.roughness = m.roughness;
  if (m.base_color_texture)
    p.color_texture = textures.get(*m.base_color_texture, TextureColorspace::kSrgb);
  if (m.metallic_roughness_texture) {
    // glTF 2.0 section 3.9.2: roughness in the green channel, metallic in the blue, linear.
    p.roughness_texture = textures.get(*m.metallic_roughness_texture, TextureColorspace::kLinear, 1);
    p.metallic_texture = textures.get(*m.metallic_roughness_texture, TextureColorspace::kLinear, 2);
  }
  if (m.normal_texture) {
    p.normal_map = textures.get(*m.normal_texture, TextureColorspace::kLinear);
    p.normal_scale = m.normal_texture->scale;
  }
  out.emission = m.emissive;
  if (m.emissive_texture && !is_black(m.emissive))
    out.emission_texture = textures.get(*m.emissive_texture, TextureColorspace::kSrgb);
  if (m.alpha_mode == GltfAlphaMode::kMask) {
    out.alpha_factor = m.alpha;
    out.alpha_cutoff = m.alpha_cutoff;
    // The alpha of an RGBA base colour texture; alpha is stored linearly in either colorspace.
    if (m.base_color_texture && textures.channels(*m.base_color_texture) >= 4)
      out.alpha_texture = textures.get(*m.base_color_texture, TextureColorspace::kSrgb, 3);
    else
      out.hidden = m.alpha < m.alpha_cutoff;
  }
  if (m.alpha_mode == GltfAlphaMode::kBlend)
    diag.warning(pointer, label + ": alphaMode BLEND is rendered opaque (penumbra has no "
                                  "partial transparency; MASK is supported as a cutout)");
  return out;
}

std::string plural(int64_t n, const char* one, const char* many) {
  return std::to_string(n) + " " + (n == 1 ? one : many);
}

}  // namespace

std::optional<GltfAsset> read_gltf_asset(const std::string& file, const std::string& pointer,
                                         const Limits& limits, const AssetFolder& assets,
                                         Diagnostics& diag) {
  if (!is_gltf_file_name(file)) {
    diag.error(pointer, "must name a .gltf or .glb file (got " + quote_user_string(file) + ")");
    return std::nullopt;
  }
  const auto path = resolve_asset_path(assets, file, pointer, diag);
  if (!path) return std::nullopt;
  const std::string name = quote_user_string(file);
  std::vector<uint8_t> bytes;
  std::string reason;
  if (!read_capped(*path, limits.max_mesh_file_bytes, &bytes, &reason)) {
    diag.error(pointer, name + ": " + reason);
    return std::nullopt;
  }
  // URIs are relative to the asset file's own folder, and must stay inside the asset folder.
  const fs::path base = fs::path(file).parent_path();
  GltfFileSource source = [&](const std::string& uri, std::vector<uint8_t>* out,
                              std::string* why) {
    const fs::path rel = (base / fs::path(uri)).lexically_normal();
    if (uri.empty() || rel.empty() || *rel.begin() == "..") {
      *why = "leaves the scene's folder";
      return false;
    }
    Diagnostics local;
    const auto resolved = resolve_asset_path(assets, rel.string(), pointer, local);
    if (!resolved) {
      const auto errors = local.take_errors();
      *why = errors.empty() ? "cannot be read" : errors.front().message;
      return false;
    }
    return read_capped(*resolved, limits.max_mesh_file_bytes, out, why);
  };
  GltfLimits gltf_limits;
  gltf_limits.max_file_bytes = limits.max_mesh_file_bytes;
  gltf_limits.max_vertices = limits.max_vertices;
  gltf_limits.max_triangles = limits.max_triangles;
  try {
    GltfAsset asset = read_gltf(bytes, name, source, gltf_limits);
    for (const std::string& w : asset.warnings) diag.warning(pointer, name + ": " + w);
    return asset;
  } catch (const GltfError& e) {
    diag.error(pointer, e.what());
  } catch (const std::bad_alloc&) {
    diag.error(pointer, name + ": out of memory while reading the file");
  }
  return std::nullopt;
}

std::optional<ParsedGltf> parse_gltf_object(ObjectReader& reader, const AffineTransform& transform,
                                            const MeshBudget& budget, const Limits& limits,
                                            const AssetFolder& assets, TextureSet& textures,
                                            bool copies_allowed) {
  Diagnostics& diag = reader.diagnostics();
  const auto file = reader.string("file", Presence::kRequired);
  if (!file) return std::nullopt;
  const std::string pointer = reader.pointer_of("file");
  const std::size_t errors_before = diag.error_count();
  const auto asset = read_gltf_asset(*file, pointer, limits, assets, diag);
  if (!asset) return std::nullopt;

  ParsedGltf out;
  GltfTextures gltf_textures(*asset, *file, pointer, textures, diag);
  // Materials: the file's, then glTF's default material (base colour 1, metallic 1,
  // roughness 1) for primitives that name none.
  std::vector<MaterialAndEmission> converted;
  for (size_t i = 0; i < asset->materials.size(); ++i) {
    const std::string label =
        quote_user_string(*file) + ": materials[" + std::to_string(i) + "]";
    converted.push_back(convert_material(asset->materials[i], gltf_textures, diag, pointer, label));
    out.materials.push_back(converted.back().params);
  }
  const uint32_t default_material = uint32_t(out.materials.size());
  out.materials.push_back(MetallicRoughnessParams{});
  converted.emplace_back();
  if (diag.error_count() != errors_before) return std::nullopt;

  // The first node to place a mesh (with a given handedness: a mirroring node's triangles are
  // re-wound, so it cannot copy an unmirrored placement) is its base; later nodes copy the
  // base's objects by M_node * M_base^-1 where they can.
  struct Base {
    AffineTransform to_world;
    AffineTransform from_world;                 // its inverse
    std::vector<std::ptrdiff_t> copies_index;   // per primitive: index in out.copies, or -1
  };
  std::map<std::pair<int, bool>, Base> bases;
  int64_t skipped_nodes = 0, hidden_parts = 0, instanced = 0;
  for (const GltfMeshInstance& instance : asset->instances) {
    const AffineTransform to_world = compose(transform, affine(instance.to_world));
    const double det = glm::determinant(to_world.linear);
    if (!(std::abs(det) > 0) || !std::isfinite(det)) {
      ++skipped_nodes;  // a zero scale hides a node (a common way to switch one off)
      continue;
    }
    const GltfMesh& mesh = asset->meshes[size_t(instance.mesh)];
    GltfPlacement placement{instance.node, instance.mesh, instance.node_name, mesh.name, {}};
    const auto key = std::make_pair(instance.mesh, det < 0);
    auto base = bases.find(key);
    const bool is_base = base == bases.end();
    if (is_base) {
      Base b{to_world, inverse(to_world), std::vector<std::ptrdiff_t>(mesh.primitives.size(), -1)};
      base = bases.emplace(key, std::move(b)).first;
    }
    for (size_t p = 0; p < mesh.primitives.size(); ++p) {
      const GltfPrimitive& prim = mesh.primitives[p];
      const MaterialAndEmission& mat =
          converted[prim.material < 0 ? default_material : size_t(prim.material)];
      if (mat.hidden) {
        ++hidden_parts;  // alpha MASK with a factor below the cutoff: nothing is left
        continue;
      }
      if (!is_base && base->second.copies_index[p] >= 0) {
        GltfCopies& copies = out.copies[size_t(base->second.copies_index[p])];
        copies.transforms.push_back(compose(to_world, base->second.from_world));
        placement.parts.push_back({copies.object, copies.transforms.back()});
        ++instanced;
        continue;
      }
      const int64_t tris = int64_t(prim.indices.size() / 3);
      if (out.triangles + tris > budget.triangles || out.vertices + int64_t(prim.positions.size()) > budget.vertices) {
        diag.error(pointer, quote_user_string(*file) + ": placing its meshes at every node exceeds the scene's limit of " +
                                std::to_string(limits.max_triangles) + " triangles (max_triangles) or " +
                                std::to_string(limits.max_vertices) + " vertices (max_vertices)");
        return std::nullopt;
      }
      std::vector<uint32_t> indices = prim.indices;
      // A mirroring transform turns counter-clockwise into clockwise: keep the front faces in
      // front (glTF 2.0 section 3.5.3).
      if (det < 0)
        for (size_t t = 0; t + 2 < indices.size(); t += 3) std::swap(indices[t + 1], indices[t + 2]);
      const std::string label = *file + " nodes[" + std::to_string(instance.node) + "] meshes[" +
                                std::to_string(instance.mesh) + "].primitives[" + std::to_string(p) + "]";
      const std::size_t before = diag.error_count();
      auto placed = place_file_mesh(reader, label, to_world, prim.positions, std::move(indices),
                                    prim.normals, prim.uvs, /*allow_empty=*/true);
      if (!placed) {
        if (diag.error_count() != before) return std::nullopt;
        continue;  // nothing left after dropping degenerate triangles (warned)
      }
      ObjectDesc object;
      const uint32_t material = prim.material < 0 ? default_material : uint32_t(prim.material);
      object.material = material;
      object.emission = mat.emission;
      object.emission_texture = mat.emission_texture;
      if (mat.alpha_texture) {
        object.alpha_texture = mat.alpha_texture;
        object.alpha_factor = mat.alpha_factor;
        object.alpha_cutoff = mat.alpha_cutoff;
      }
      if (!is_black(object.emission)) out.any_emission = true;
      out.triangles += int64_t(placed->indices.size() / 3);
      out.vertices += int64_t(placed->positions.size());
      const bool copyable = copies_allowed && is_black(object.emission) && !object.emission_texture;
      object.shape = std::move(*placed);
      if (is_base && copyable) {
        base->second.copies_index[p] = std::ptrdiff_t(out.copies.size());
        out.copies.push_back(GltfCopies{out.objects.size(), {}});
      }
      placement.parts.push_back({out.objects.size(), AffineTransform{}});
      out.objects.push_back(std::move(object));
    }
    out.placements.push_back(std::move(placement));
  }
  // Primitives no other node uses need no instances.
  out.copies.erase(std::remove_if(out.copies.begin(), out.copies.end(),
                                  [](const GltfCopies& c) { return c.transforms.empty(); }),
                   out.copies.end());
  if (hidden_parts > 0)
    diag.warning(pointer, quote_user_string(*file) + ": " + plural(hidden_parts, "primitive", "primitives") +
                              " left out: alphaMode MASK with an alpha factor below the cutoff");
  if (skipped_nodes > 0)
    diag.warning(pointer, quote_user_string(*file) + ": " + plural(skipped_nodes, "node", "nodes") +
                              " with a zero scale (hidden) left out");

  int64_t spots = 0;
  for (const GltfLight& light : asset->lights) {
    const AffineTransform to_world = compose(transform, affine(light.to_world));
    const Spectrum power = light.color * float(light.intensity);
    if (light.type == GltfLightType::kDirectional) {
      const glm::dvec3 d = to_world.vector(glm::dvec3(0, 0, -1));
      if (!(glm::length(d) > 0)) continue;
      out.lights.push_back(DirectionalLightDesc{to_float(glm::normalize(d)), power});
    } else if (light.type == GltfLightType::kPoint) {
      out.lights.push_back(PointLightDesc{to_float(to_world.point(glm::dvec3(0.0))), power});
    } else {
      ++spots;
    }
  }
  if (spots > 0)
    diag.warning(pointer, quote_user_string(*file) + ": " + plural(spots, "spot light", "spot lights") +
                              " left out (penumbra has no spot lights yet)");
  if (out.objects.empty() && out.lights.empty())
    diag.warning(pointer, quote_user_string(*file) + ": places no mesh and no light");

  int64_t materials_used = 0;
  {
    std::vector<bool> used(out.materials.size(), false);
    for (const ObjectDesc& o : out.objects) used[o.material] = true;
    for (bool u : used) materials_used += u;
  }
  out.use.pointer = pointer;
  out.use.path = *file;
  out.use.summary = "glTF: " + plural(int64_t(asset->meshes.size()), "mesh", "meshes") + " at " +
                    plural(int64_t(asset->instances.size()), "node", "nodes") + " -> " +
                    plural(out.triangles, "triangle", "triangles") +
                    (instanced > 0 ? " (+ " + plural(instanced, "instanced copy", "instanced copies") + ")" : "") + ", " +
                    plural(materials_used, "material", "materials") + ", " +
                    plural(int64_t(asset->images.size()), "image", "images") + ", " +
                    plural(int64_t(asset->lights.size()), "light", "lights") + ", " +
                    plural(int64_t(asset->cameras.size()), "camera", "cameras");
  return out;
}

}  // namespace penumbra::api
