#pragma once
// The wavefront driver's surface stages: the step of every path that hit a surface of one
// BSDF model (Lambertian, conductors, plastics, dielectrics and glTF's metallic-roughness;
// constant or textured parameters,
// with or without a normal map), after its
// emission, as loops over arrays: the light choice and light sample (light_kernels.h), the
// BSDF's value, pdf and MIS weight towards the light, the shadow ray and its contribution, then
// the BSDF's sample (lane_bsdfs.h), the throughput, the spawned ray and Russian roulette. One
// path at a time these are many short dependent chains; the surfaces of one model are often
// most of a bounce's paths, so a stage carries a whole step per path against the arrays it
// fills and reads back (the light stage alone, a third of this, did not pay:
// docs/performance.md).
//
// The results are path_scatter's to the bit for the path integrator: the same operations in the
// same order (glm's dot is (x + y) + z, to_world is (s x + t y) + n z, std::max and std::min
// as their comparisons), the branches as selects between values all lanes compute, the file
// compiled without contraction into fused multiply-adds (renderer/CMakeLists.txt). A light
// without a kernel (spheres, emitting meshes, spot lights, environment maps: light_kernels.h)
// is sampled lane by lane by its own Light::sample, the rest of the step in the lanes.
#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "renderer/render/light_kernels.h"
#include "renderer/render/path_step.h"

namespace penumbra {

// The surfaces a stage takes (lane_bsdfs.h has their models).
enum class StageModel : uint8_t {
  kLambert,         // DiffuseBsdf
  kRoughConductor,  // ConductorBsdf with a microfacet lobe (not a smooth mirror)
  kSmoothPlastic,   // PlasticBsdf with a smooth coating
  kRoughPlastic,    // PlasticBsdf with a rough coating tabulated on square nodes (ior >= 1)
  kRoughDielectric, // DielectricBsdf with microfacet lobes (not smooth, not index-matched)
  kSmoothConductor, // ConductorBsdf's mirror
  kSmoothDielectric,  // DielectricBsdf's Dirac reflection and refraction (not index-matched)
  kMetallicRoughness,  // MetallicRoughnessBsdf (glTF) with a microfacet lobe (not the mirror)
};
inline constexpr StageModel kStageModels[] = {
    StageModel::kLambert,         StageModel::kRoughConductor,  StageModel::kSmoothPlastic,
    StageModel::kRoughPlastic,    StageModel::kRoughDielectric, StageModel::kSmoothConductor,
    StageModel::kSmoothDielectric, StageModel::kMetallicRoughness};

class SurfaceStage {
 public:
  SurfaceStage(const Scene& scene, StageModel model);
  // (Not copied: its LightRows refer to its own lights_.)
  SurfaceStage(const SurfaceStage&) = delete;
  SurfaceStage& operator=(const SurfaceStage&) = delete;
  const Scene& scene() const { return scene_; }
  StageModel model() const { return model_; }

  // Whether the stage can take hits on `object`: its material is one of the stage's model
  // (textured parameters and a normal map are looked up per hit in add_many; a hit whose looked-up
  // parameters leave the model, such as a roughness texture at zero, is not `staged`).
  bool takes(uint32_t object) const { return params_of_[object] >= 0; }

  // Empty, with room for `paths` lanes.
  void start(size_t paths);
  // Queues n paths after path_arrive, lane by lane in order: lane i takes the driver's slot
  // k = slots[i], whose path is live[k] (its state states[live[k]]), whose hit is hits[k] and
  // whose prefetched sampler values are column j = hit_of[k] of the bounce's samples:
  // x[j + d * stride], y[j + d * stride] for dimensions d = 0..4 and its get_1d_2d pairs' 1D
  // values z[j] and z[j + stride] (BounceSamples' dimension-major layout, with kBouncePairs or
  // kBounceWithoutLightPairs; the stage reads the light pair's only with more than one light,
  // the lobe pair's only for models with a lobe choice, which the caller computes:
  // needs_lobe_choice). `next_event`: whether the step estimates direct light (path_scatter's
  // condition for a surface with a diffuse lobe: the scene has lights), which decides which
  // values are whose.
  void add_many(size_t n, const uint32_t* slots, const uint32_t* live, const uint32_t* hit_of,
                const PathState* states, const SurfaceHit* hits, const float* x,
                const float* y, const float* z, size_t stride, bool next_event);
  // Whether the stage's model picks among lobes with the step's 1D lobe value.
  bool needs_lobe_choice() const {
    return model_ != StageModel::kLambert && model_ != StageModel::kRoughConductor &&
           model_ != StageModel::kSmoothConductor;
  }
  // Takes every queued path's step (`next_event` as for add_many).
  void compute(const IntegratorSettings& settings, bool next_event);
  // (With next_event, the step estimates direct light unless the model's lobes are all Dirac
  // deltas, as path_scatter decides; that also decides which sampler values are whose.)

  size_t size() const { return count_; }
  // Hands the step's results, as path_scatter leaves them, to the driver's per-slot arrays:
  // for lane i with slot k = slot(i) and path p = live[k], goes_on[k] and has_shadow[k], the
  // shadow query in shadows[k] (written whether or not there is one: the slot is the lane's
  // own), and, for a path that goes on, states[p] and cursors[p] (its ray, throughput, MIS
  // record, eta, depth, and the sampler dimensions it took). Lanes whose looked-up parameters
  // leave the model (a textured hit's may) get none of this: they are listed in *unstaged for
  // the caller to take their step with path_scatter. Returns how many next-event rays the
  // step counted.
  uint64_t deliver(const uint32_t* live, PathState* states, Sampler::Cursor* cursors,
                   uint8_t* goes_on, uint8_t* has_shadow, ShadowQuery* shadows,
                   std::vector<uint32_t>* unstaged) const;
  uint32_t slot(size_t lane) const { return slot_[lane]; }
  // Whether the step reads a bounce's Russian roulette value at the lobe pair's first dimension
  // (its lobes are all Dirac: path_scatter takes lobe and direction at the light pair's place).
  bool roulette_at_lobe_dimension() const { return !estimates_light(true); }

 private:
  // Whether path_scatter estimates direct light at this model's surfaces (given lights): not
  // where every lobe is a Dirac delta.
  bool estimates_light(bool next_event) const {
    return next_event && model_ != StageModel::kSmoothConductor &&
           model_ != StageModel::kSmoothDielectric;
  }

  // A surface's constants (lane::Params without the tables).
  struct SurfaceParams {
    Spectrum colour;
    float alpha = 0.f, eta = 1.f, spec_weight = 0.f, diffuse_scale = 0.f;
    int32_t table = 0, nodes = 0;
    float metallic = 0.f, roughness = 0.f, e_avg = 0.f, dielectric_avg = 0.f;
    Spectrum f_ms{0.f};
  };
  // q's fields for this stage's model from BSDF b; false if b is not of the model (or has a
  // non-finite colour, or coating tables the stage does not hold).
  bool fill_params(const SurfaceBsdf& b, SurfaceParams* q) const;
  // Lane i's model parameters from q.
  [[gnu::always_inline]] inline void write_params(size_t i, const SurfaceParams& q);
  // Lane i's parameters looked up at a textured hit (and its normal map's frame and normal).
  [[gnu::noinline]] void add_textured(size_t i, const PathState& s, const SurfaceHit& hit);
  // The light samples of the lanes whose chosen light has no kernel (own_code_lanes_), each by
  // its Light::sample, into the lanes' light arrays.
  [[gnu::noinline]] void sample_own_code_lights();

  const Scene& scene_;
  StageModel model_;
  StagedLights lights_;
  // Each kernel's per-lane constants (the lanes' lights' rows of lights_' tables).
  LightRows quad_rows_, sphere_rows_, point_rows_;
  std::vector<int32_t> params_of_;  // per object: index into params_, or -1
  // Per object: whether its material is textured (parameters looked up at each hit).
  std::vector<uint8_t> textured_of_;
  std::vector<SurfaceParams> params_;
  // The rough plastics' coating tables, one after another (lane::Tables), and whose they are.
  std::vector<float> table_cosines_, table_values_;
  std::vector<const CoatingTables*> tables_;
  const float* albedo_table_ = nullptr;  // ggx_albedo_table(), for the metallic-roughness model
  size_t count_ = 0;
  std::vector<uint32_t> slot_;
  // Inputs per lane.
  std::vector<float> p_[3], p_error_[3], ng_[3], ns_[3], dir_[3], beta_[3], colour_[3];
  std::vector<float> alpha_, coat_eta_, spec_weight_, diffuse_scale_;
  std::vector<float> metallic_, roughness_, e_avg_, dielectric_avg_, f_ms_[3];
  std::vector<int32_t> table_, nodes_;
  std::vector<float> time_, eta_, u_light_, u_point_[2], u_lobe_, u_dir_[2], u_rr_;
  std::vector<vec3> choose_p_, choose_n_;  // the lanes' points and normals, for a light tree
  std::vector<int32_t> depth_;
  // The light sample per lane.
  std::vector<int32_t> light_, light_ok_, l_delta_;
  std::vector<float> l_wi_[3], l_distance_, l_pdf_, l_p_[3], l_error_[3], l_n_[3], l_value_[3], l_pmf_;
  std::vector<uint32_t> own_code_lanes_;  // lanes whose light is StagedLights::kOwnCode
  // Per lane: its light's StagedLights kind (-1: no light) and index among that kind's lights.
  std::vector<int32_t> lane_kind_, lane_slot_;
  // Lanes whose light is a textured quad, and one light's lanes and uvs: their radiance is
  // looked up for all of them at once (look_up_emission, into looked_up_).
  std::vector<uint32_t> emission_lanes_, emission_of_;
  std::vector<float> emission_u_, emission_v_;
  [[gnu::noinline]] void look_up_emission();
  // Those of them whose light is the environment, and their requests and samples for its
  // Light::sample_many.
  std::vector<uint32_t> environment_lanes_;
  std::vector<vec3> many_refs_;
  std::vector<float> many_times_;
  std::vector<vec2> many_u_;
  std::vector<LightSample> many_out_;
  std::unique_ptr<bool[]> many_ok_;
  // The lanes whose looked-up parameters leave the model (a textured hit's may), and the
  // normal-mapped lanes: their mask (set in compute, only when there are any: the kernels'
  // mapped case then costs the other batches nothing), tangent frames' s and t, mapped normals.
  std::vector<uint32_t> unfit_, mapped_lanes_;
  // The hits on every textured material, one list per material and kind, looked up together
  // when the stage computes: an image colour as the only textured parameter
  // (Material::color_image) or a conductor's or dielectric's roughness (roughness_image), the
  // lanes' parameter replaced; any other textured parameters (kParameters: several of them, a
  // metallic-roughness material's), all its parameter textures looked up together and each
  // hit's BSDF built from its texels (Material::bsdf_of_texels) and taken apart by fill_params;
  // and every normal map (kNormal).
  struct TextureLookups {
    enum Kind : uint8_t { kColour, kRoughness, kNormal, kParameters };
    const Material* material;
    Kind kind;
    std::vector<uint32_t> lanes;
    std::vector<float> u, v;
    std::vector<int32_t> params;  // kParameters: each hit's index into params_
  };
  std::vector<TextureLookups> texture_lookups_;
  // Per object: index into texture_lookups_ of its parameters' list, and of its normal map's;
  // -1 for none.
  std::vector<int32_t> texture_lookups_of_, normal_lookups_of_;
  // The list of `kind` for material m (made on first use).
  int32_t lookups_for(const Material& m, TextureLookups::Kind kind);
  std::vector<float> looked_up_[3], looked_up_roughness_, looked_up_metallic_;
  // Each list's texels (eval_many), made the lanes' colours, GGX alphas or mapped normals as
  // bsdf_at and fill_params make them.
  [[gnu::noinline]] void look_up_textures();
  std::vector<int32_t> mapped_;
  std::vector<float> frame_s_[3], frame_t_[3], mapped_n_[3];
  // Results per lane.
  std::vector<int32_t> staged_, alive_, has_shadow_, nee_ray_, dims_, prev_delta_;
  std::vector<float> s_origin_[3], s_dir_[3], s_t_max_, s_contrib_[3];
  std::vector<float> origin_[3], wo_[3], beta_out_[3], prev_pdf_, eta_out_;
};

}  // namespace penumbra
