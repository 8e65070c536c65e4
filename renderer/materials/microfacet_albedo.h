#pragma once
// Directional albedo of single-scattering GGX reflection, tabulated over (cos theta,
// roughness): what the energy-compensated glTF material (metallic_roughness.h) needs per hit,
// for any roughness a texture may give. The table is computed by quadrature
// (ggx_albedo_row_by_quadrature) and shipped as source (ggx_albedo_table.inc, written by
// tools/tables/generate_ggx_albedo_table), as Cycles ships its precomputed BSDF tables.
//
// For a GGX surface of alpha = r^2 with the separable Smith G (microfacet.h), incident
// direction wi with cos theta_i = mu, and h the half vector:
//   E(mu, r)  = \int D G / (4 mu cos_o) cos_o dwo                  (Fresnel = 1)
//   E5(mu, r) = \int (1 - wi.h)^5 D G / (4 mu cos_o) cos_o dwo     (Schlick's weight)
// so that the albedo with Schlick's Fresnel F = f0 + (1 - f0)(1 - wi.h)^5 is
// f0 (E - E5) + E5 (the split of Karis 2013, "Real Shading in Unreal Engine 4"), and the
// cosine-weighted hemispherical averages E_avg = 2 \int E mu dmu, E5_avg likewise (Kulla and
// Conty 2017, "Revisiting Physically Based Shading at Imageworks").
#include "renderer/core/math.h"

namespace penumbra {

struct MicrofacetAlbedo {
  float e = 1.f;   // E
  float e5 = 0.f;  // E5
};

// Bilinear lookup in the table. Roughness 0 is the smooth limit: E = 1, E5 = (1 - mu)^5 exactly.
MicrofacetAlbedo ggx_albedo(float cos_theta, float roughness);
// The averages over the cosine-weighted hemisphere of the same (interpolated) table, so that
// 2 \int ggx_albedo(mu, r) mu dmu equals ggx_albedo_average(r) up to rounding: the
// energy-compensation terms then conserve energy exactly for white surfaces.
MicrofacetAlbedo ggx_albedo_average(float roughness);

// Table resolution (nodes along cos theta and along roughness), for tests.
inline constexpr int kAlbedoTableRes = 48;

// The table ggx_albedo interpolates, for the surface stages' lane version of it
// (render/lane_bsdfs.h): E and E5 of node (roughness j, cos i) at [2 (j kAlbedoTableRes + i)]
// and the next float.
const float* ggx_albedo_table();

// Row j of the table (roughness j / (kAlbedoTableRes - 1)) at the cos nodes i / (kAlbedoTableRes
// - 1), and its averages, by quadrature over the visible normals (about 20 ms a row): what the
// shipped table holds, to float rounding.
struct MicrofacetAlbedoRow {
  MicrofacetAlbedo albedo[kAlbedoTableRes];
  MicrofacetAlbedo average;
};
MicrofacetAlbedoRow ggx_albedo_row_by_quadrature(int j);

}  // namespace penumbra
