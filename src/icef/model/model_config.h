// The model half of a run config ("model": {...} in a config file): architecture, mask,
// confidence and rendering settings. Every key, its default and meaning is in docs/config.md
// (generated from Bind()). Training settings live in TrainConfig.
#pragma once

#include <string>
#include <vector>

#include "icef/field/confidence.h"
#include "icef/field/deformation_field.h"
#include "icef/field/region_mask.h"
#include "icef/field/static_field.h"
#include "icef/io/config_schema.h"
#include "icef/model/method.h"
#include "icef/render/compositing.h"
#include "icef/render/importance_sampler.h"
#include "icef/render/occupancy_grid.h"
#include "icef/render/ray_sampler.h"

namespace icef {

// Image renders and evaluation (model/render_image.h).
struct ImageRenderOptions {
  // s x s rays per pixel, averaged. 1 (the pixel centre): training rays through pixel centres
  // learn each pixel's value there, and averaging around it blurs; 2 was 0.31 dB worse on the
  // diverse validation suite (docs/results/priors_validation.md) at 4x the cost.
  int supersample = 1;
  double transmittance_eps = 1e-2;  // stop a ray once its transmittance is below this
  // Samples per ray, as a multiple of the training sampler's (sampler.num_samples; in marching mode
  // the steps shrink by it). The midpoints of the training count step over surfaces that a warp
  // compresses along the ray (a puffed cheek's edge shows the background through the face); 2 was
  // +0.41 dB held-out, +0.59 dB far-tier on the validation identities (docs/results/priors_validation.md).
  int sample_factor = 2;

  bool operator==(const ImageRenderOptions&) const = default;
};

// Carving the occupancy grid to the visual hull of the training masks (train/visual_hull.h).
struct VisualHullConfig {
  bool enabled = true;  // images with alpha only
  int margin_px = 2;    // footprint dilation, pixels
  int min_views = 0;    // cells fewer training views see are carved (0 = ceil(K / 2))

  bool operator==(const VisualHullConfig&) const = default;
};

// One nested block per component, each the component's own Options struct ("static_field":
// {"grid": {"finest_resolution": 512}} is StaticFieldOptions::grid.finest_resolution): the
// defaults are the structs' in-class ones, one source checked by train/config_defaults_test.cc.
// Options fields that are not config keys (static_field.condition_dims, bf16_inference and bf16_training,
// sampler.stratified) are filled in by the accessors below, which every user of the config calls.
struct ModelConfig {
  std::string method = "icef-prior";  // icef-prior | warp-prior | icef | icef-no-id | icef-no-conf |
                                      // icef-uniform | warp | nerface
  StaticFieldOptions static_field;
  DeformationFieldOptions deformation;
  ConfidenceOptions confidence;
  RegionMaskOptions region_mask;
  VisualHullConfig visual_hull;
  RaySamplerOptions sampler;
  ImportanceOptions importance;  // bound as sampler.importance_*: training rays only
  OccupancyGridOptions occupancy;
  CompositeOptions compositing;  // training rays (renders: render.transmittance_eps)
  ImageRenderOptions render;
  // The *-prior methods: scale each sample's colour by the change of light the face model's
  // expression brings to its surface, under a light fitted to the training images
  // (field/prior_shading.h, model/prior_light.h).
  bool prior_shading = true;
  // The *-prior methods: fit the subject's expression style (face/expression_style.h) with its shape
  // to the training frames' landmarks, so the prior warps as this subject performs the expressions
  // its training frames show (model/face_prior.h).
  bool prior_style = true;
  // Renders, eval and occupancy updates: MLP products in BF16 with FP32 sums (AVX512-BF16 CPUs).
  bool bf16_inference = StaticFieldOptions{}.bf16_inference;
  // Training passes (forward, backward, weight gradients) likewise; weights and Adam stay FP32.
  bool bf16_training = StaticFieldOptions{}.bf16_training;

  void Bind(ConfigSchema& s);
  Status Validate() const;

  Method ParsedMethod() const;  // requires Validate()
  StaticFieldOptions StaticOptions(int expression_dims) const;
  DeformationFieldOptions DeformationOptions() const;
  RaySamplerOptions SamplerOptions(bool stratified) const;
  // Renders and evaluation: the sampler's midpoints at render.sample_factor times its density.
  RaySamplerOptions RenderSamplerOptions() const;
};

}  // namespace icef
