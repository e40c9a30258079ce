#include "icef/model/model_config.h"

namespace icef {

namespace {

void BindGrid(ConfigSchema& s, nn::HashGridOptions* o) {
  s.Int("num_levels", &o->num_levels, "hash grid levels L");
  s.Int("features_per_level", &o->features_per_level, "hash grid features per level F");
  s.Int("log2_table_size", &o->log2_table_size, "log2 of the hashed table size T per level");
  s.Number("base_resolution", &o->base_resolution, "coarsest hash grid resolution (cells per axis)");
  s.Number("finest_resolution", &o->finest_resolution, "finest hash grid resolution (cells per axis)");
}

void BindStaticField(ConfigSchema& s, StaticFieldOptions* o) {
  s.Block("grid", [o](ConfigSchema& g) { BindGrid(g, &o->grid); });
  s.Int("density_hidden", &o->density_hidden, "density MLP hidden width");
  s.Int("geo_features", &o->geo_features, "density MLP outputs (log-density first, all feed the colour MLP)");
  s.IntArray("color_hidden", &o->color_hidden, "colour MLP hidden widths");
  s.Int("sh_degree", &o->sh_degree, "spherical-harmonics degree of the view-direction encoding (1-4)");
  s.Float("density_bias", &o->density_bias,
          "added to the log-density before exp (negative: space starts nearly empty)");
}

void BindDeformation(ConfigSchema& s, DeformationFieldOptions* o) {
  s.Int("num_frequencies", &o->num_frequencies, "deformation field positional-encoding frequencies");
  s.IntArray("hidden", &o->hidden, "deformation MLP hidden widths");
  s.Float("output_init_scale", &o->output_init_scale,
          "initial output-layer weight scale of the deformation MLP");
}

void BindRegionMask(ConfigSchema& s, RegionMaskOptions* o) {
  s.Float("brow_margin", &o->brow_margin, "brow capsule radius (fraction of inter-ocular distance)");
  s.Float("eye_margin", &o->eye_margin, "eye capsule radius (fraction of inter-ocular distance)");
  s.Float("mouth_margin", &o->mouth_margin, "lip capsule radius (fraction of inter-ocular distance)");
  s.Float("softness", &o->softness, "half-width of the soft edge (fraction of inter-ocular distance)");
}

void BindVisualHull(ConfigSchema& s, VisualHullConfig* o) {
  s.Bool("enabled", &o->enabled,
         "carve the occupancy grid to the visual hull of the training masks (images with alpha)");
  s.Int("margin_px", &o->margin_px, "footprint dilation in pixels");
  s.Int("min_views", &o->min_views, "carve cells whose centre fewer training views see (0 = ceil(K/2))");
}

void BindOccupancy(ConfigSchema& s, OccupancyGridOptions* o) {
  s.Int("resolution", &o->resolution, "occupancy grid cells per axis");
  s.Float("threshold", &o->threshold, "density above which an occupancy cell is occupied");
  s.Float("decay", &o->decay, "occupancy EMA-of-max decay per update");
}

void BindRender(ConfigSchema& s, ImageRenderOptions* o) {
  s.Int("supersample", &o->supersample,
        "image renders average s x s rays per pixel (1 = the pixel centre, where training rays learn each "
        "pixel's value; averaging rays around it blurs)");
  s.Number("transmittance_eps", &o->transmittance_eps,
           "renders and evaluation: stop a ray once its transmittance is below this (what is left behind can "
           "change a pixel by at most this fraction: 1e-2 is at most 2.5/255); training composites to "
           "compositing.transmittance_eps");
  s.Int("sample_factor", &o->sample_factor,
        "renders and evaluation place this many times sampler.num_samples samples per ray (marching: steps "
        "this many times shorter); the training count's midpoints step over surfaces a warp compresses");
}

// The flat keys of configs and checkpoints written before the blocks, and their current paths.
void BindFlatSpellings(ConfigSchema& s) {
  static const std::pair<const char*, const char*> kRenamed[] = {
      {"grid_levels", "static_field.grid.num_levels"},
      {"grid_features", "static_field.grid.features_per_level"},
      {"grid_log2_table_size", "static_field.grid.log2_table_size"},
      {"grid_base_resolution", "static_field.grid.base_resolution"},
      {"grid_finest_resolution", "static_field.grid.finest_resolution"},
      {"density_hidden", "static_field.density_hidden"},
      {"geo_features", "static_field.geo_features"},
      {"color_hidden", "static_field.color_hidden"},
      {"sh_degree", "static_field.sh_degree"},
      {"density_bias", "static_field.density_bias"},
      {"deform_frequencies", "deformation.num_frequencies"},
      {"deform_hidden", "deformation.hidden"},
      {"deform_init_scale", "deformation.output_init_scale"},
      {"kappa_lambda", "confidence.lambda"},
      {"mask_brow_margin", "region_mask.brow_margin"},
      {"mask_eye_margin", "region_mask.eye_margin"},
      {"mask_mouth_margin", "region_mask.mouth_margin"},
      {"mask_softness", "region_mask.softness"},
      {"visual_hull", "visual_hull.enabled"},
      {"hull_margin_px", "visual_hull.margin_px"},
      {"hull_min_views", "visual_hull.min_views"},
      {"samples_per_ray", "sampler.num_samples"},
      {"occupancy_resolution", "occupancy.resolution"},
      {"occupancy_threshold", "occupancy.threshold"},
      {"occupancy_decay", "occupancy.decay"},
      {"transmittance_eps", "compositing.transmittance_eps"},
      {"render_supersample", "render.supersample"},
      {"render_transmittance_eps", "render.transmittance_eps"},
  };
  for (const auto& [old_key, current] : kRenamed) s.Renamed(old_key, current);
}

}  // namespace

void ModelConfig::Bind(ConfigSchema& s) {
  s.String("method", &method,
           "method: icef, icef-no-id, icef-no-conf, icef-uniform, warp, nerface, icef-prior or warp-prior "
           "(docs/design.md §2, §2.1)");
  s.Block("static_field", [this](ConfigSchema& b) { BindStaticField(b, &static_field); });
  s.Block("deformation", [this](ConfigSchema& b) { BindDeformation(b, &deformation); });
  s.Block("confidence", [this](ConfigSchema& b) {
    b.Number("lambda", &confidence.lambda, "confidence length scale: kappa = exp(-delta / lambda)");
  });
  s.Block("region_mask", [this](ConfigSchema& b) { BindRegionMask(b, &region_mask); });
  s.Block("visual_hull", [this](ConfigSchema& b) { BindVisualHull(b, &visual_hull); });
  s.Block("sampler", [this](ConfigSchema& b) {
    b.Int(
        "num_samples", &sampler.num_samples,
        "samples per training ray over the ray/aabb interval, one per jittered stratum (fewer, deeper strata "
        "smear "
        "the face's colour along the training rays and blur every other view: 48 did, and 96 still a little; "
        "docs/results/sampler_samples)");
    b.Int("importance_samples", &importance.num_samples,
          "training: fine samples per ray placed by the num_samples coarse samples' compositing weights "
          "(each coarse "
          "stratum cut into as many sub-strata as its share of the weight; render/importance_sampler.h); 0 = "
          "train on "
          "the coarse samples themselves. Measured on a validation identity: sharper but grainy, 0.5-1.7 dB "
          "below 144 "
          "stratified samples at the same cost; off by default (docs/results/importance_sampling)");
    b.Float(
        "importance_uniform", &importance.uniform,
        "share of each ray's importance samples spread over its coarse strata by length rather than weight");
  });
  s.Block("occupancy", [this](ConfigSchema& b) { BindOccupancy(b, &occupancy); });
  s.Block("compositing", [this](ConfigSchema& b) {
    b.Number("transmittance_eps", &compositing.transmittance_eps,
             "training: stop compositing a ray once its transmittance is below this (renders: "
             "render.transmittance_eps)");
  });
  s.Block("render", [this](ConfigSchema& b) { BindRender(b, &render); });
  s.Bool(
      "prior_shading", &prior_shading,
      "icef-prior and warp-prior: scale each sample's colour by the change of light that the expression "
      "brings "
      "to the face model's surface (its normal there against the neutral surface's at the canonical point), "
      "under a light fitted to the training images' skin before training (field/prior_shading.h, "
      "model/prior_light.h): the shading a warp of a static field cannot show");
  s.Bool(
      "prior_style", &prior_style,
      "icef-prior and warp-prior: fit the subject's expression style (each expression's gain, the jaw hinge, "
      "the "
      "smile's corner and the brows' shift; face/expression_style.h) with its shape to the training frames' "
      "landmarks, each field with a prior around the face model's generic style; an expression no training "
      "frame "
      "shows keeps the generic style");
  s.Bool("bf16_inference", &bf16_inference,
         "renders, evaluation and occupancy updates multiply in BF16 with FP32 sums on CPUs with AVX512-BF16 "
         "(about "
         "1.6-2x the FP32 products' rate, depending on the CPU)");
  s.Bool("bf16_training", &bf16_training,
         "training's forward and backward MLP products (weight gradients included) in BF16 with FP32 sums on "
         "CPUs "
         "with AVX512-BF16 (about 11% more samples/s; observed PSNR on the validation identities +0.04 dB); "
         "weights, "
         "gradients and Adam stay FP32");
  BindFlatSpellings(s);
}

Status ModelConfig::Validate() const {
  ICEF_RETURN_IF_ERROR(ParseMethod(method).status().WithContext("method"));
  ICEF_RETURN_IF_ERROR(StaticOptions(1).Validate().WithContext("static_field"));
  ICEF_RETURN_IF_ERROR(DeformationOptions().Validate().WithContext("deformation"));
  ICEF_RETURN_IF_ERROR(confidence.Validate().WithContext("confidence"));
  ICEF_RETURN_IF_ERROR(region_mask.Validate().WithContext("region_mask"));
  if (visual_hull.margin_px < 0) return Status::Error("visual_hull.margin_px must be >= 0");
  if (visual_hull.min_views < 0) return Status::Error("visual_hull.min_views must be >= 0");
  ICEF_RETURN_IF_ERROR(SamplerOptions(true).Validate().WithContext("sampler"));
  ICEF_RETURN_IF_ERROR(importance.Validate().WithContext("sampler"));
  ICEF_RETURN_IF_ERROR(occupancy.Validate().WithContext("occupancy"));
  ICEF_RETURN_IF_ERROR(compositing.Validate().WithContext("compositing"));
  if (render.supersample < 1 || render.supersample > 8)
    return Status::Error("render.supersample must be in 1..8");
  if (!(render.transmittance_eps >= 0.0 && render.transmittance_eps < 1.0))
    return Status::Error("render.transmittance_eps must be in [0, 1)");
  if (render.sample_factor < 1 || render.sample_factor > 8)
    return Status::Error("render.sample_factor must be in 1..8");
  ICEF_RETURN_IF_ERROR(RenderSamplerOptions().Validate().WithContext("render.sample_factor"));
  return Status::Ok();
}

Method ModelConfig::ParsedMethod() const { return ParseMethod(method).value(); }

StaticFieldOptions ModelConfig::StaticOptions(int expression_dims) const {
  StaticFieldOptions o = static_field;
  o.bf16_inference = bf16_inference;
  o.bf16_training = bf16_training;
  auto m = ParseMethod(method);
  o.condition_dims = (m.ok() && TraitsOf(*m).entangled_beta) ? expression_dims : 0;
  return o;
}

DeformationFieldOptions ModelConfig::DeformationOptions() const {
  DeformationFieldOptions o = deformation;
  o.bf16_inference = bf16_inference;
  o.bf16_training = bf16_training;
  return o;
}

RaySamplerOptions ModelConfig::SamplerOptions(bool stratified) const {
  RaySamplerOptions o = sampler;
  o.stratified = stratified;
  return o;
}

RaySamplerOptions ModelConfig::RenderSamplerOptions() const {
  RaySamplerOptions o = SamplerOptions(false);
  const int f = render.sample_factor;
  o.num_samples *= f;
  o.max_samples *= f;
  o.step_size /= static_cast<float>(f);
  o.cone_angle /= static_cast<float>(f);
  return o;
}

}  // namespace icef
