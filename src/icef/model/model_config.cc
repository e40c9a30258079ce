#include "icef/model/model_config.h"

namespace icef {

void ModelConfig::Bind(ConfigSchema& s) {
  s.String("method", &method, "method: icef, icef-no-id, icef-no-conf, icef-uniform, warp, nerface, icef-prior or warp-prior (DESIGN.md §2, §2.1)");
  s.Int("grid_levels", &grid_levels, "hash grid levels L");
  s.Int("grid_features", &grid_features, "hash grid features per level F");
  s.Int("grid_log2_table_size", &grid_log2_table_size, "log2 of the hashed table size T per level");
  s.Number("grid_base_resolution", &grid_base_resolution, "coarsest hash grid resolution (cells per axis)");
  s.Number("grid_finest_resolution", &grid_finest_resolution, "finest hash grid resolution (cells per axis)");
  s.Int("density_hidden", &density_hidden, "density MLP hidden width");
  s.Int("geo_features", &geo_features, "density MLP outputs (log-density first, all feed the colour MLP)");
  s.IntArray("color_hidden", &color_hidden, "colour MLP hidden widths");
  s.Int("sh_degree", &sh_degree, "spherical-harmonics degree of the view-direction encoding (1-4)");
  s.Int("deform_frequencies", &deform_frequencies, "deformation field positional-encoding frequencies");
  s.IntArray("deform_hidden", &deform_hidden, "deformation MLP hidden widths");
  s.Float("deform_init_scale", &deform_init_scale, "initial output-layer weight scale of the deformation MLP");
  s.Number("kappa_lambda", &kappa_lambda, "confidence length scale: kappa = exp(-delta / kappa_lambda)");
  s.Float("mask_brow_margin", &mask_brow_margin, "region mask: brow capsule radius (fraction of inter-ocular distance)");
  s.Float("mask_eye_margin", &mask_eye_margin, "region mask: eye capsule radius (fraction of inter-ocular distance)");
  s.Float("mask_mouth_margin", &mask_mouth_margin, "region mask: lip capsule radius (fraction of inter-ocular distance)");
  s.Float("mask_softness", &mask_softness, "region mask: half-width of the soft edge (fraction of inter-ocular distance)");
  s.Bool("visual_hull", &visual_hull, "carve the occupancy grid to the visual hull of the training masks (images with alpha)");
  s.Int("hull_margin_px", &hull_margin_px, "visual hull: footprint dilation in pixels");
  s.Int("hull_min_views", &hull_min_views, "visual hull: carve cells whose centre fewer training views see (0 = ceil(K/2))");
  s.Float("density_bias", &density_bias, "added to the log-density before exp (negative: space starts nearly empty)");
  s.Int("samples_per_ray", &samples_per_ray, "samples per ray over the ray/aabb interval");
  s.Int("occupancy_resolution", &occupancy_resolution, "occupancy grid cells per axis");
  s.Float("occupancy_threshold", &occupancy_threshold, "density above which an occupancy cell is occupied");
  s.Float("occupancy_decay", &occupancy_decay, "occupancy EMA-of-max decay per update");
  s.Number("transmittance_eps", &transmittance_eps,
           "training: stop compositing a ray once its transmittance is below this (renders: render_transmittance_eps)");
  s.Int("render_supersample", &render_supersample,
        "image renders average s x s rays per pixel (1 = the pixel centre: with train.pixel_jitter the field already "
        "returns each pixel's average, and averaging again blurs)");
  s.Number("render_transmittance_eps", &render_transmittance_eps,
           "renders and evaluation: stop a ray once its transmittance is below this (what is left behind can change "
           "a pixel by at most this fraction: 1e-2 is at most 2.5/255); training composites to transmittance_eps");
  s.Bool("bf16_inference", &bf16_inference,
         "renders, evaluation and occupancy updates multiply in BF16 with FP32 sums on CPUs with AVX512-BF16 (about 2x "
         "the MLP throughput); training passes are always FP32");
}

Status ModelConfig::Validate() const {
  ICEF_RETURN_IF_ERROR(ParseMethod(method).status().WithContext("method"));
  ICEF_RETURN_IF_ERROR(StaticOptions(1).Validate());
  if (hull_margin_px < 0) return Status::Error("hull_margin_px must be >= 0");
  if (hull_min_views < 0) return Status::Error("hull_min_views must be >= 0");
  if (render_supersample < 1 || render_supersample > 8) return Status::Error("render_supersample must be in 1..8");
  if (!(render_transmittance_eps >= 0.0 && render_transmittance_eps < 1.0))
    return Status::Error("render_transmittance_eps must be in [0, 1)");
  ICEF_RETURN_IF_ERROR(DeformationOptions().Validate());
  ICEF_RETURN_IF_ERROR(MaskOptions().Validate().WithContext("mask"));
  ICEF_RETURN_IF_ERROR(ConfidenceOpts().Validate().WithContext("kappa_lambda"));
  ICEF_RETURN_IF_ERROR(SamplerOptions(true).Validate().WithContext("samples_per_ray"));
  ICEF_RETURN_IF_ERROR(OccupancyOptions().Validate().WithContext("occupancy"));
  ICEF_RETURN_IF_ERROR(CompositeOpts().Validate().WithContext("transmittance_eps"));
  return Status::Ok();
}

Method ModelConfig::ParsedMethod() const { return ParseMethod(method).value(); }

StaticFieldOptions ModelConfig::StaticOptions(int expression_dims) const {
  StaticFieldOptions o;
  o.grid.num_levels = grid_levels;
  o.grid.features_per_level = grid_features;
  o.grid.log2_table_size = grid_log2_table_size;
  o.grid.base_resolution = grid_base_resolution;
  o.grid.finest_resolution = grid_finest_resolution;
  o.density_hidden = density_hidden;
  o.geo_features = geo_features;
  o.color_hidden = color_hidden;
  o.sh_degree = sh_degree;
  o.density_bias = density_bias;
  o.bf16_inference = bf16_inference;
  auto m = ParseMethod(method);
  o.condition_dims = (m.ok() && TraitsOf(*m).entangled_beta) ? expression_dims : 0;
  return o;
}

DeformationFieldOptions ModelConfig::DeformationOptions() const {
  DeformationFieldOptions o;
  o.num_frequencies = deform_frequencies;
  o.hidden = deform_hidden;
  o.output_init_scale = deform_init_scale;
  o.bf16_inference = bf16_inference;
  return o;
}

RegionMaskOptions ModelConfig::MaskOptions() const {
  RegionMaskOptions o;
  o.brow_margin = mask_brow_margin;
  o.eye_margin = mask_eye_margin;
  o.mouth_margin = mask_mouth_margin;
  o.softness = mask_softness;
  return o;
}

ConfidenceOptions ModelConfig::ConfidenceOpts() const {
  ConfidenceOptions o;
  o.lambda = kappa_lambda;
  return o;
}

RaySamplerOptions ModelConfig::SamplerOptions(bool stratified) const {
  RaySamplerOptions o;
  o.num_samples = samples_per_ray;
  o.stratified = stratified;
  return o;
}

OccupancyGridOptions ModelConfig::OccupancyOptions() const {
  OccupancyGridOptions o;
  o.resolution = occupancy_resolution;
  o.threshold = occupancy_threshold;
  o.decay = occupancy_decay;
  return o;
}

CompositeOptions ModelConfig::CompositeOpts() const {
  CompositeOptions o;
  o.transmittance_eps = transmittance_eps;
  return o;
}

}  // namespace icef
