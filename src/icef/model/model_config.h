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

struct ModelConfig {
  std::string method = "icef-prior";  // icef-prior | warp-prior | icef | icef-no-id | icef-no-conf | icef-uniform | warp | nerface
  int grid_levels = 16;               // hash grid levels L
  int grid_features = 2;              // features per level F
  int grid_log2_table_size = 17;      // log2 of the hashed table size T per level
  double grid_base_resolution = 16;   // coarsest grid resolution (cells per axis over the aabb)
  double grid_finest_resolution = 512;  // finest grid resolution
  int density_hidden = 64;            // density MLP hidden width
  int geo_features = 16;              // density MLP outputs (log-density + colour features)
  std::vector<int> color_hidden = {64, 64};  // colour MLP hidden widths
  int sh_degree = 2;                  // view-direction SH degree (few-shot: low, view-dependence overfits)
  int deform_frequencies = 6;         // deformation positional-encoding frequencies
  std::vector<int> deform_hidden = {64, 64, 64};  // deformation MLP hidden widths
  float deform_init_scale = 0.01f;    // initial output-layer scale of the deformation MLP
  double kappa_lambda = 0.5;          // confidence length scale: kappa = exp(-delta / kappa_lambda)
  float mask_brow_margin = 0.15f;     // region-mask capsule radius around brows (fraction of inter-ocular distance)
  float mask_eye_margin = 0.15f;      // ... around the eyes
  float mask_mouth_margin = 0.25f;    // ... around the lips
  float mask_softness = 0.08f;        // half-width of the mask's soft edge (fraction of inter-ocular distance)
  bool visual_hull = true;            // carve the occupancy grid to the visual hull of the training masks (alpha only)
  int hull_margin_px = 2;             // visual hull footprint dilation, pixels
  int hull_min_views = 0;             // visual hull: cells fewer training views see are carved (0 = ceil(K / 2))
  float density_bias = -4.f;          // added to the log-density before exp (negative: space starts nearly empty)
  int samples_per_ray = 48;           // samples per ray over the ray/aabb interval
  int render_supersample = 2;         // image renders: s x s rays per pixel, averaged
  int occupancy_resolution = 64;      // occupancy grid cells per axis
  float occupancy_threshold = 0.5f;   // density above which a cell is occupied
  float occupancy_decay = 0.9f;       // EMA-of-max decay of stored cell densities per update
  double transmittance_eps = 1e-4;    // stop compositing a ray below this transmittance
  bool bf16_inference = true;         // renders/eval/occupancy: MLP products in BF16, FP32 sums (AVX512-BF16 CPUs)

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
