#include "icef/train/train_config.h"

#include <algorithm>
#include <cmath>
#include <set>

#include "icef/io/checkpoint.h"
#include "icef/io/config_override.h"

namespace icef {

namespace {

// The step count, the batch and the learning rates.
void BindStepsAndRates(ConfigSchema& s, TrainConfig& c) {
  s.Int64("steps", &c.steps, "optimiser steps");
  s.Number("time_budget_seconds", &c.time_budget_seconds,
           "stop after this much wall time in seconds (0 = no limit)");
  s.Int("batch_rays", &c.batch_rays, "rays per step");
  s.Number("lr_grid", &c.lr_grid, "Adam learning rate of the hash grid");
  s.Number("lr_mlp", &c.lr_mlp, "Adam learning rate of the static field's MLPs");
  s.Number("lr_deform", &c.lr_deform, "Adam learning rate of the deformation MLP");
  s.Number("lr_final_factor", &c.lr_final_factor,
           "learning rates decay exponentially to this factor at the last step");
}

// The weights of the loss terms and priors other than L_depth.
void BindLossWeights(ConfigSchema& s, TrainConfig& c) {
  s.Number("lambda_id", &c.lambda_id, "weight of L_id, identity preservation outside the expression regions");
  s.Number(
      "lambda_id_prior", &c.lambda_id_prior,
      "weight of L_id for the methods on the face-model prior (icef-prior), where it acts on the learned "
      "residual R_phi alone: no residual warping outside mouth, eyes and brows");
  s.Number("lambda_smooth", &c.lambda_smooth,
           "weight of L_smooth, deformation smoothness at the region boundary");
  s.Number("lambda_mask", &c.lambda_mask,
           "weight of the alpha-mask loss (auxiliary; datasets with alpha only)");
  s.Number(
      "lambda_distortion", &c.lambda_distortion,
      "weight of the mip-NeRF 360 distortion loss, distances in aabb diagonals (few-shot prior; 0 = off)");
  s.Number(
      "lambda_occlusion", &c.lambda_occlusion,
      "weight of the occlusion sparsity prior: density behind what the training rays already hit (0 = off)");
  s.Number("lambda_occlusion_prior", &c.lambda_occlusion_prior,
           "weight of the occlusion sparsity prior for the methods on the face-model prior (icef-prior, "
           "warp-prior; 0 = off: their face-model depth prior holds the geometry, and this prior eroded the "
           "back of the head, which few training rays see)");
  s.Bool("occlusion_prior_in_regions", &c.occlusion_prior_in_regions,
         "on the face-model prior, the occlusion sparsity prior (train.lambda_occlusion_prior) inside the "
         "expression regions (brows, eyes, mouth) alone: each sample's term weighted by the region mask M, "
         "the back of the head left alone (off: on validation identities it cost expression everywhere, "
         "the eyes included; docs/results/near_tier_variants)");
  s.Number("lambda_symmetry", &c.lambda_symmetry,
           "weight of the left-right symmetry prior: opacity (and colour) of canonical samples against their "
           "mirror images across the face's landmark symmetry plane (few-shot prior; 0 = off)");
}

// L_depth: its weight, pixels, window and reach, and the unseen views.
void BindDepthPrior(ConfigSchema& s, TrainConfig& c) {
  s.Number(
      "lambda_depth_prior", &c.lambda_depth_prior,
      "weight of L_depth: each training ray through the expression regions (brows, eyes, mouth) pulled to "
      "the depth at which it meets the fitted face model at its frame's expression, distances in aabb "
      "diagonals (icef-prior, warp-prior; 0 = off)");
  s.String(
      "depth_prior_region", &c.depth_prior_region,
      "the pixels L_depth acts on: \"expression\" (the expression region: brows, eyes, mouth and what lies "
      "between them, as train.region_rays), \"eyes\" (each eye's landmark hull) or \"face\" (the hull of all "
      "68 "
      "landmarks, jaw line to brows, with the expression region)");
  s.Number("depth_prior_window", &c.depth_prior_window,
           "half-width of L_depth's window about the face model's depth, in aabb diagonals: each sample's "
           "offset from it is clamped to the window, so the weight a ray keeps far behind the face (where it "
           "leaves the head) pulls no harder than weight just past the window (0 = no window)");
  s.Number(
      "depth_prior_reach", &c.depth_prior_reach,
      "L_depth's reach behind the face model's depth, in aabb diagonals: weight farther behind (inside the "
      "head, and where the ray leaves it) and the light that passes through the ray count as one "
      "termination at the reach, so the far side of the head is left alone and a hole is no way to meet "
      "the prior (0 = no reach: every sample counts, transmitted light costs nothing)");
  s.Int(
      "depth_prior_views", &c.depth_prior_views,
      "unseen views per training frame whose rays L_depth also pulls to the face model's depth: the frame's "
      "camera turned about the face (by up to depth_prior_view_yaw / depth_prior_view_pitch degrees), its "
      "expression region's pixel rays that meet the fitted face model; no colour, only depth (0 = off)");
  s.Int("depth_prior_view_rays", &c.depth_prior_view_rays,
        "unseen-view rays per step (train.depth_prior_views), on top of train.batch_rays");
  s.Number("depth_prior_view_yaw", &c.depth_prior_view_yaw,
           "largest turn (degrees) of an unseen view about the head's up axis");
  s.Number("depth_prior_view_pitch", &c.depth_prior_view_pitch,
           "largest turn (degrees) of an unseen view about its camera's right axis");
  s.String(
      "depth_prior_view_region", &c.depth_prior_view_region,
      "the unseen views' pixels: \"expression\" (the expression region of the face model's own landmarks "
      "projected into the view), \"upper\" (that region without the mouth: brows and eyes) or \"face\" (the "
      "filled hull of all 68 as well: nose, cheeks, chin)");
}

// The settings of L_sym and L_smooth, and how the training rays are drawn.
void BindTermSettingsAndRays(ConfigSchema& s, TrainConfig& c) {
  s.Number("symmetry_colour", &c.symmetry_colour,
           "weight of the symmetry prior's colour part relative to its opacity part (0 = geometry only)");
  s.Int("symmetry_max_samples", &c.symmetry_max_samples, "samples per step mirrored by the symmetry prior");
  s.Number("smooth_epsilon", &c.smooth_epsilon,
           "finite-difference offset of L_smooth (half-extent units of the aabb)");
  s.Int("smooth_max_samples", &c.smooth_max_samples, "boundary samples per step used by L_smooth");
  s.Bool("random_background", &c.random_background,
         "composite targets over a random colour per ray, rendered over the same (images with alpha only)");
  s.Bool("pixel_jitter", &c.pixel_jitter,
         "cast each training ray through a random point of its pixel instead of its centre (off: the field "
         "then learns each pixel's average over the whole pixel, and a render at the centre averages the "
         "truth's pixel a second time: softer faces, -0.28 dB held-out on the validation identities)");
  s.Number(
      "region_rays", &c.region_rays,
      "share of each step's rays drawn from the training frames' expression regions (brows, eyes and mouth "
      "by their 2D landmarks, the region icef eval scores expressions in; frames without landmarks add "
      "none); "
      "the rest over all pixels (0 = all uniform)");
}

// Coarse-to-fine annealing and the start: the density start and the start trials.
void BindStart(ConfigSchema& s, TrainConfig& c) {
  s.Int("grid_anneal_steps", &c.grid_anneal_steps,
        "coarse-to-fine hash grid: levels beyond the 4 coarsest switch on over these steps (0 = off)");
  s.Int("anneal_steps", &c.anneal_steps,
        "coarse-to-fine: deformation frequencies switch on over these steps (0 = off)");
  s.Int(
      "density_start_steps", &c.density_start_steps,
      "steps of a start that fits the static field's density to the fitted face model's neutral head before "
      "training (icef-prior, warp-prior; 0 = the uniform start)");
  s.Number(
      "density_start_erosion", &c.density_start_erosion,
      "head units the density start's head lies inside the fitted face model's surface (the fit's jaw and "
      "neck are not the subject's: density seeded outside the subject stays as a shell held-out views see)");
  s.Number("density_start_log_density", &c.density_start_log_density,
           "log-density the density start gives the inside of the head (the empty field's is "
           "model.static_field.density_bias)");
  s.Int(
      "start_trials", &c.start_trials,
      "initialisations tried before training (1 = the seed's alone): each trains start_trial_steps steps and "
      "the one with the lowest batch loss over the last quarter of them is trained from the start");
  s.Int("start_trial_steps", &c.start_trial_steps, "steps each of the start_trials initialisations trains");
}

// The occupancy grid, checkpoints, logs, evaluation, seed, threads and the NaN guard.
void BindBookkeeping(ConfigSchema& s, TrainConfig& c) {
  s.Int("occupancy_warmup", &c.occupancy_warmup,
        "steps before the occupancy grid starts skipping empty space");
  s.Int("occupancy_every", &c.occupancy_every, "steps between occupancy grid updates");
  s.Int("checkpoint_every", &c.checkpoint_every, "steps between checkpoints (0 = only at the end)");
  s.Int("log_every", &c.log_every, "steps between lines of MODEL/train_log.jsonl");
  s.Int("eval_every", &c.eval_every,
        "steps between held-out PSNR evaluations on observed-tier test frames (0 = off)");
  s.Int64("seed", &c.seed, "root seed of every random draw");
  s.Int("threads", &c.threads, "worker threads (0 = all cores)");
  s.String(
      "on_nonfinite", &c.on_nonfinite,
      "a non-finite loss term or gradient: \"stop\" training with an error naming the step and term, or "
      "\"skip\" the optimiser step (counted as skipped_steps in summary.json; the 11th non-finite step in a "
      "row still stops training)");
}

}  // namespace

void TrainConfig::Bind(ConfigSchema& s) {
  BindStepsAndRates(s, *this);
  BindLossWeights(s, *this);
  BindDepthPrior(s, *this);
  BindTermSettingsAndRays(s, *this);
  BindStart(s, *this);
  BindBookkeeping(s, *this);
}

LossWeights TrainConfig::Losses(bool has_alpha) const {
  LossWeights w;
  w.lambda_id = lambda_id;
  w.lambda_id_prior = lambda_id_prior;
  w.lambda_occlusion_prior = lambda_occlusion_prior;
  w.occlusion_prior_in_regions = occlusion_prior_in_regions;
  w.lambda_smooth = lambda_smooth;
  w.lambda_mask = has_alpha ? lambda_mask : 0.0;
  w.lambda_distortion = lambda_distortion;
  w.lambda_depth_prior = lambda_depth_prior;
  w.depth_prior_window = depth_prior_window;
  w.depth_prior_reach = depth_prior_reach;
  w.lambda_occlusion = lambda_occlusion;
  w.lambda_symmetry = lambda_symmetry;
  w.symmetry_colour = symmetry_colour;
  w.symmetry_max_samples = symmetry_max_samples;
  w.smooth_epsilon = smooth_epsilon;
  w.smooth_max_samples = smooth_max_samples;
  return w;
}

Status TrainConfig::Validate() const {
  auto positive = [](double v) { return std::isfinite(v) && v > 0; };
  auto non_negative = [](double v) { return std::isfinite(v) && v >= 0; };
  if (steps < 1) return Status::Error("train.steps must be >= 1");
  if (!non_negative(time_budget_seconds)) return Status::Error("train.time_budget_seconds must be >= 0");
  if (batch_rays < 1) return Status::Error("train.batch_rays must be >= 1");
  if (!(region_rays >= 0 && region_rays <= 1)) return Status::Error("train.region_rays must be in [0, 1]");
  if (!positive(lr_grid) || !positive(lr_mlp) || !positive(lr_deform))
    return Status::Error("train.lr_grid, lr_mlp and lr_deform must be positive");
  if (!positive(lr_final_factor) || lr_final_factor > 1)
    return Status::Error("train.lr_final_factor must be in (0, 1]");
  if (!non_negative(lambda_id)) return Status::Error("train.lambda_id must be a finite number >= 0");
  if (!non_negative(lambda_id_prior))
    return Status::Error("train.lambda_id_prior must be a finite number >= 0");
  if (!non_negative(lambda_occlusion_prior))
    return Status::Error("train.lambda_occlusion_prior must be a finite number >= 0");
  if (!non_negative(lambda_smooth)) return Status::Error("train.lambda_smooth must be a finite number >= 0");
  if (!non_negative(lambda_mask)) return Status::Error("train.lambda_mask must be a finite number >= 0");
  if (!non_negative(lambda_distortion))
    return Status::Error("train.lambda_distortion must be a finite number >= 0");
  if (!non_negative(lambda_depth_prior))
    return Status::Error("train.lambda_depth_prior must be a finite number >= 0");
  if (!non_negative(depth_prior_window))
    return Status::Error("train.depth_prior_window must be a finite number >= 0");
  if (!non_negative(depth_prior_reach))
    return Status::Error("train.depth_prior_reach must be a finite number >= 0");
  if (depth_prior_views < 0) return Status::Error("train.depth_prior_views must be >= 0");
  if (depth_prior_view_rays < 0) return Status::Error("train.depth_prior_view_rays must be >= 0");
  if (!non_negative(depth_prior_view_yaw) || depth_prior_view_yaw > 90)
    return Status::Error("train.depth_prior_view_yaw must be a number of degrees in [0, 90]");
  if (!non_negative(depth_prior_view_pitch) || depth_prior_view_pitch > 90)
    return Status::Error("train.depth_prior_view_pitch must be a number of degrees in [0, 90]");
  if (!non_negative(lambda_occlusion))
    return Status::Error("train.lambda_occlusion must be a finite number >= 0");
  if (!non_negative(lambda_symmetry))
    return Status::Error("train.lambda_symmetry must be a finite number >= 0");
  if (!non_negative(symmetry_colour))
    return Status::Error("train.symmetry_colour must be a finite number >= 0");
  if (symmetry_max_samples < 1) return Status::Error("train.symmetry_max_samples must be >= 1");
  if (!positive(smooth_epsilon)) return Status::Error("train.smooth_epsilon must be positive");
  if (!non_negative(density_start_erosion))
    return Status::Error("train.density_start_erosion must be a finite number >= 0");
  if (!std::isfinite(density_start_log_density))
    return Status::Error("train.density_start_log_density must be finite");
  if (start_trials < 1 || start_trial_steps < 4)
    return Status::Error("train.start_trials must be >= 1 and train.start_trial_steps >= 4");
  if (smooth_max_samples < 1) return Status::Error("train.smooth_max_samples must be >= 1");
  if (anneal_steps < 0 || grid_anneal_steps < 0 || density_start_steps < 0 || occupancy_warmup < 0 ||
      occupancy_every < 1 || checkpoint_every < 0 || log_every < 1 || eval_every < 0)
    return Status::Error(
        "train: anneal_steps, grid_anneal_steps, density_start_steps, occupancy_warmup, checkpoint_every, "
        "eval_every must be >= 0 and "
        "occupancy_every, log_every >= 1");
  if (threads < 0) return Status::Error("train.threads must be >= 0");
  if (depth_prior_region != "expression" && depth_prior_region != "eyes" && depth_prior_region != "face")
    return Status::Error("train.depth_prior_region must be \"expression\", \"eyes\" or \"face\", got \"" +
                         depth_prior_region + "\"");
  if (depth_prior_view_region != "expression" && depth_prior_view_region != "upper" &&
      depth_prior_view_region != "face")
    return Status::Error(
        "train.depth_prior_view_region must be \"expression\", \"upper\" or \"face\", got \"" +
        depth_prior_view_region + "\"");
  if (on_nonfinite != "stop" && on_nonfinite != "skip")
    return Status::Error("train.on_nonfinite must be \"stop\" or \"skip\", got \"" + on_nonfinite + "\"");
  return Status::Ok();
}

Status RunConfig::Validate() const {
  ICEF_RETURN_IF_ERROR(model.Validate().WithContext("model"));
  return train.Validate();
}

Json RunConfig::ToJson() const {
  Json j;
  j["model"] = WriteConfig(model);
  j["train"] = WriteConfig(train);
  return j;
}

namespace {
Status ApplyJson(const Json& json, const std::string& origin, const std::filesystem::path& base_dir,
                 ConfigSchema::OldKeys old_keys, std::set<std::string>* visited, RunConfig* config) {
  ICEF_ASSIGN_OR_RETURN(const JsonObjectView root, JsonObjectView::Make(json, origin, ""));
  const std::vector<std::string> unknown = root.UnknownKeys({"parent", "model", "train"});
  if (!unknown.empty()) return root.Error(unknown.front(), "unknown key (valid keys: parent, model, train)");
  if (root.Has("parent")) {
    ICEF_ASSIGN_OR_RETURN(const std::string parent, root.String("parent"));
    const std::filesystem::path path = base_dir / parent;
    if (!visited->insert(std::filesystem::weakly_canonical(path).string()).second)
      return root.Error("parent", "cycle of parent configs through " + path.string());
    ICEF_ASSIGN_OR_RETURN(const Json parent_json, ReadJsonFile(path));
    ICEF_RETURN_IF_ERROR(
        ApplyJson(parent_json, path.string(), path.parent_path(), old_keys, visited, config));
  }
  if (root.Has("model")) {
    ICEF_ASSIGN_OR_RETURN(const JsonObjectView m, root.Object("model"));
    ICEF_RETURN_IF_ERROR(ReadConfig(m, &config->model, old_keys));
  }
  if (root.Has("train")) {
    ICEF_ASSIGN_OR_RETURN(const JsonObjectView t, root.Object("train"));
    ICEF_RETURN_IF_ERROR(ReadConfig(t, &config->train));
  }
  return Status::Ok();
}
}  // namespace

Result<RunConfig> RunConfig::FromJson(const Json& json, const std::string& origin,
                                      ConfigSchema::OldKeys old_keys) {
  RunConfig config;
  std::set<std::string> visited;
  ICEF_RETURN_IF_ERROR(ApplyJson(json, origin, std::filesystem::path("."), old_keys, &visited, &config));
  ICEF_RETURN_IF_ERROR(config.Validate().WithContext(origin));
  return config;
}

Result<RunConfig> RunConfig::FromFile(const std::filesystem::path& path) {
  ICEF_ASSIGN_OR_RETURN(const Json json, ReadJsonFile(path));
  RunConfig config;
  std::set<std::string> visited = {std::filesystem::weakly_canonical(path).string()};
  ICEF_RETURN_IF_ERROR(
      ApplyJson(json, path.string(), path.parent_path(), ConfigSchema::OldKeys::kReject, &visited, &config));
  ICEF_RETURN_IF_ERROR(config.Validate().WithContext(path.string()));
  return config;
}

Status RunConfig::ApplyOverride(const std::string& assignment) {
  ICEF_ASSIGN_OR_RETURN(const ConfigOverride o, ParseConfigOverride(assignment));
  Json patch;
  patch[o.section] = o.SectionPatch();
  std::set<std::string> visited;
  RunConfig updated = *this;
  ICEF_RETURN_IF_ERROR(
      ApplyJson(patch, "--set " + assignment, ".", ConfigSchema::OldKeys::kReject, &visited, &updated));
  ICEF_RETURN_IF_ERROR(updated.Validate().WithContext("--set " + assignment));
  *this = updated;
  return Status::Ok();
}

uint64_t RunConfig::Hash() const { return Fnv1a64(ToJson().dump()); }

double DeformationAnnealing(const RunConfig& config, int64_t step) {
  return DeformationAnnealing(config.model, config.train.anneal_steps, step);
}

std::vector<float> GridLevelWeights(const RunConfig& config, int64_t step) {
  return GridLevelWeights(config.model, config.train.grid_anneal_steps, step);
}

std::string ConfigDocumentation() {
  std::string out;
  ConfigSchema model_schema, train_schema;
  ModelConfig model;
  TrainConfig train;
  model.Bind(model_schema);
  train.Bind(train_schema);
  out += "## `model`\n\n| key | default | meaning |\n|---|---|---|\n" + model_schema.MarkdownRows();
  out += "\n## `train`\n\n| key | default | meaning |\n|---|---|---|\n" + train_schema.MarkdownRows();
  return out;
}

}  // namespace icef
