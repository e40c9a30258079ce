// Internal to model/: the reusable buffers of AvatarModel's training step and renders, shared with
// the loss terms (model/losses.h). Nothing outside model/ includes this header.
#pragma once

#include <cstdint>
#include <vector>

#include "icef/field/deformation.h"
#include "icef/field/static_field.h"
#include "icef/render/compositing.h"
#include "icef/render/ray_sampler.h"

namespace icef {

// Resizes v to `size` elements (keeps the allocation; nothing allocates once grown).
template <typename V>
void Fit(V& v, size_t size) {
  v.resize(size);
}

// One batch's state, [n] = samples, [R] = rays. World frame unless named canonical.
struct ModelWorkspace {
  RaySamples samples;
  // Importance sampling's coarse pass (config importance): its samples, expressions [m, B], warp
  // and the density at each (no gradients).
  RaySamples coarse;
  std::vector<float> coarse_betas, coarse_offsets, coarse_canonical, coarse_sigma;
  std::vector<uint8_t> coarse_cavity;
  StaticFieldContext coarse_static_ctx;
  DeformationContext coarse_deform_ctx;
  std::vector<float> positions, dirs, betas;  // [n, 3], [n, 3], [n, expression_dim]
  std::vector<float> offsets, residual;       // [n, 3] D_final(x) - x and its learned residual R_phi
  std::vector<float> canonical;               // [n, 3] x + offsets
  std::vector<float> sigma, rgb;              // [n], [n, 3] the fields at the samples
  std::vector<float> mask_values, extras;     // [n] M(x); renders: [n, 2] per-sample extras
  std::vector<uint8_t> cavity;                // [n] inside the face model's open mouth
  std::vector<int32_t> color_rows;            // training: the samples the pixel rays composite
  std::vector<float> ray_sigma;               // training: one ray's densities with the cavity's
  // Prior shading (field/prior_shading.h): the face model's normals [n, 3] (observed, canonical), the
  // ratio s [n] (empty: not applied) and, in training, the colours before it [n, 3].
  std::vector<float> normals_obs, normals_can, shade, rgb_unshaded;
  std::vector<int64_t> shade_index;  // the samples dense enough to shade, and their gathered inputs/normals
  std::vector<float> shade_positions, shade_betas, shade_obs, shade_can;
  CompositeOutputs<float> composite;
  // Gradients of the loss: w.r.t. ray colour [R, 3], opacity [R] and sample weights ([n], or empty
  // when no term has one), then w.r.t. sigma [n], rgb [n, 3] and canonical positions [n, 3].
  std::vector<float> d_color, d_opacity, d_weights, d_sigma, d_rgb, d_canonical;
  StaticFieldContext static_ctx;
  DeformationContext deform_ctx;
  DeformationWorkspace warp_ws;
  // L_smooth: 2m points (x_i, then x_i + delta_i).
  std::vector<float> smooth_positions, smooth_betas, smooth_offsets, smooth_d_offsets, smooth_weight;
  std::vector<int64_t> smooth_index;
  DeformationContext smooth_ctx;
  // L_sym: m samples (gathered) and their mirror images.
  std::vector<int64_t> sym_index;
  std::vector<float> sym_positions, sym_dirs, sym_sigma_a, sym_rgb_a, sym_sigma_b, sym_rgb_b, sym_dt;
  std::vector<float> sym_d_sigma_a, sym_d_rgb_a, sym_d_sigma_b, sym_d_rgb_b, sym_d_positions;
  StaticFieldContext sym_ctx;
};

}  // namespace icef
