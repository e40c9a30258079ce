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
#include "icef/render/occupancy_grid.h"
#include "icef/render/ray_sampler.h"

namespace icef {

// Every default below that a component has is the component's own (its Options struct's in-class
// default): one source, checked by train/config_defaults_test.cc.
struct ModelConfig {
 private:
  inline static const StaticFieldOptions kStatic{};
  inline static const DeformationFieldOptions kDeformation{};
  inline static const RegionMaskOptions kMask{};
  inline static const OccupancyGridOptions kOccupancy{};

 public:
  std::string method = "icef-prior";  // icef-prior | warp-prior | icef | icef-no-id | icef-no-conf | icef-uniform | warp | nerface
  int grid_levels = kStatic.grid.num_levels;  // hash grid levels L
  int grid_features = kStatic.grid.features_per_level;  // features per level F
  int grid_log2_table_size = kStatic.grid.log2_table_size;  // log2 of the hashed table size T per level
  double grid_base_resolution = kStatic.grid.base_resolution;  // coarsest grid resolution (cells per axis over the aabb)
  double grid_finest_resolution = kStatic.grid.finest_resolution;  // finest grid resolution
  int density_hidden = kStatic.density_hidden;  // density MLP hidden width
  int geo_features = kStatic.geo_features;  // density MLP outputs (log-density + colour features)
  std::vector<int> color_hidden = kStatic.color_hidden;  // colour MLP hidden widths
  int sh_degree = kStatic.sh_degree;  // view-direction SH degree (few-shot: low, view-dependence overfits)
  int deform_frequencies = kDeformation.num_frequencies;  // deformation positional-encoding frequencies
  std::vector<int> deform_hidden = kDeformation.hidden;  // deformation MLP hidden widths
  float deform_init_scale = kDeformation.output_init_scale;  // initial output-layer scale of the deformation MLP
  double kappa_lambda = ConfidenceOptions{}.lambda;  // confidence length scale: kappa = exp(-delta / kappa_lambda)
  float mask_brow_margin = kMask.brow_margin;  // region-mask capsule radius around brows (fraction of inter-ocular distance)
  float mask_eye_margin = kMask.eye_margin;  // ... around the eyes
  float mask_mouth_margin = kMask.mouth_margin;  // ... around the lips
  float mask_softness = kMask.softness;  // half-width of the mask's soft edge (fraction of inter-ocular distance)
  bool visual_hull = true;            // carve the occupancy grid to the visual hull of the training masks (alpha only)
  int hull_margin_px = 2;             // visual hull footprint dilation, pixels
  int hull_min_views = 0;             // visual hull: cells fewer training views see are carved (0 = ceil(K / 2))
  float density_bias = kStatic.density_bias;  // added to the log-density before exp (negative: space starts nearly empty)
  int samples_per_ray = RaySamplerOptions{}.num_samples;  // samples per ray over the ray/aabb interval
  // Image renders: s x s rays per pixel, averaged. 1 (the pixel centre): training rays already
  // learn each pixel's average (train.pixel_jitter), and averaging again blurs; 2 was 0.31 dB
  // worse on the diverse validation suite (docs/results/priors_validation.md) at 4x the cost.
  int render_supersample = 1;
  double render_transmittance_eps = 1e-2;  // renders and eval: stop a ray once its transmittance is below this
  int occupancy_resolution = kOccupancy.resolution;  // occupancy grid cells per axis
  float occupancy_threshold = kOccupancy.threshold;  // density above which a cell is occupied
  float occupancy_decay = kOccupancy.decay;  // EMA-of-max decay of stored cell densities per update
  double transmittance_eps = CompositeOptions{}.transmittance_eps;  // stop compositing a ray below this transmittance
  bool bf16_inference = kStatic.bf16_inference;  // renders/eval/occupancy: MLP products in BF16, FP32 sums (AVX512-BF16 CPUs)

  void Bind(ConfigSchema& s);
  Status Validate() const;

  Method ParsedMethod() const;  // requires Validate()
  StaticFieldOptions StaticOptions(int expression_dims) const;
  DeformationFieldOptions DeformationOptions() const;
  RegionMaskOptions MaskOptions() const;
  ConfidenceOptions ConfidenceOpts() const;
  RaySamplerOptions SamplerOptions(bool stratified) const;
  OccupancyGridOptions OccupancyOptions() const;
  CompositeOptions CompositeOpts() const;
};

}  // namespace icef
