// Run configs: {"parent": "other.json", "model": {...ModelConfig keys}, "train": {...TrainConfig
// keys}}. A parent is read first (paths relative to the child file) and the child overrides the
// keys it names, as instant-ngp's configs do. Unknown keys are errors that list the valid keys.
// docs/config.md lists every key, its default and meaning.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "icef/io/config_schema.h"
#include "icef/model/coarse_to_fine.h"
#include "icef/model/losses.h"
#include "icef/model/model_config.h"

namespace icef {

struct TrainConfig {
  int64_t steps = 2000;  // optimiser steps
  double time_budget_seconds =
      0;                  // stop after this much wall time (0 = no limit); the step count still bounds it
  int batch_rays = 4096;  // rays per step
  // Adam learning rate of the hash grid: 3e-2, against 1e-2 before, is +0.49 to +1.62 dB on every
  // diverse validation identity at 1000 steps (docs/results/priors_validation.md, 2026-11-24) and
  // shortens the slow start of a nearly empty field.
  double lr_grid = 5e-2;
  double lr_mlp = 1e-3;          // Adam learning rate of the static field's MLPs
  double lr_deform = 1e-3;       // Adam learning rate of the deformation MLP
  double lr_final_factor = 0.1;  // learning rates decay exponentially to this factor at the last step
  double lambda_id = 1.0;        // weight of L_id (identity preservation outside the expression regions)
  // Weight of L_id for the methods on the face-model prior (icef-prior), where it acts on the
  // learned residual R_phi alone; chosen on validation identities 101-106 (docs/results/lambda_id_prior/).
  double lambda_id_prior = 100.0;
  double lambda_smooth = 1e-4;       // weight of L_smooth (deformation smoothness at the region boundary)
  double lambda_mask = 0.1;          // weight of the alpha-mask loss (images with alpha only)
  double lambda_distortion = 0.035;  // weight of the mip-NeRF 360 distortion loss (0 = off)
  double smooth_epsilon =
      LossWeights{}.smooth_epsilon;  // finite-difference offset of L_smooth (half-extent units)
  int smooth_max_samples = LossWeights{}.smooth_max_samples;  // boundary samples per step used by L_smooth
  double lambda_occlusion = 1e-4;  // weight of the occlusion sparsity prior (0 = off)
  // Its weight for the methods on the face-model prior (icef-prior, warp-prior): 0, since L_depth
  // holds their geometry and L_occ eroded the back of the head there; on validation identities
  // 101-108 PSNR +0.56 to +0.68 dB at an unchanged expression (docs/results/near_tier_variants).
  double lambda_occlusion_prior = 0.0;
  // On the prior, L_occ inside the expression regions alone (each sample's term times the mask M);
  // off: on validation identities 101-108 it cost expression in every tier, the eyes included.
  bool occlusion_prior_in_regions = false;
  double lambda_symmetry = 0.1;  // weight of the left-right symmetry prior L_sym (0 = off)
  // Weight of L_depth: the expression regions' training rays pulled to the fitted face model's depth
  // (methods on the face-model prior; 0 = off; train/face_depth.h). 30, with the window and reach
  // below, chosen on validation identities 101-108 (docs/results/near_tier_variants): more of the
  // expression and nearer the truth's identity in every tier, for a few hundredths of a dB.
  double lambda_depth_prior = 30.0;
  std::string depth_prior_region =
      "expression";  // L_depth's pixels: "expression" (brows, eyes, mouth), "eyes" or "face"
  double depth_prior_window =
      0.01;  // L_depth's window half-width about the target, aabb diagonals (0 = none)
  double depth_prior_reach =
      0.05;  // L_depth's reach behind the target, aabb diagonals (0 = none; render/depth_loss.h)
  // L_depth on rays from unseen views too: each training frame's camera turned about the face by up
  // to +-yaw / +-pitch degrees, views per frame (0 = off), rays per step from them (train/face_depth.h).
  // On by default since 2026-11-29 (ninth): more of the expression in every tier, mostly in the eyes,
  // identity and PSNR within their noise (docs/results/near_tier_variants/).
  int depth_prior_views = 4;
  int depth_prior_view_rays = 512;
  double depth_prior_view_yaw = 20.0;
  double depth_prior_view_pitch = 10.0;
  std::string depth_prior_view_region =
      "expression";  // the unseen views' pixels: "expression", "upper" or "face"
  double symmetry_colour =
      LossWeights{}.symmetry_colour;  // weight of L_sym's colour part relative to its opacity part
  int symmetry_max_samples = LossWeights{}.symmetry_max_samples;  // samples per step mirrored by L_sym
  // Training rays through random points of their pixels (true) or through the centres (false, the
  // default: a jittered ray learns its pixel's average at every point of the pixel, so a render at
  // the centre shows the truth's pixel averaged a second time, and the face comes out soft;
  // docs/results/priors_validation.md, 2026-11-25).
  bool pixel_jitter = false;
  // The share of each step's rays drawn from the training frames' expression regions (brows, eyes
  // and mouth by their 2D landmarks, the region icef eval scores expressions in); the rest are
  // drawn over all pixels. Frames without landmarks contribute no region. Validation 101-104, two
  // training seeds: docs/results/region_rays.
  double region_rays = 0.15;
  bool random_background = true;  // train over random background colours (images with alpha only)
  int grid_anneal_steps = kDefaultGridAnnealSteps;  // coarse-to-fine hash grid: levels beyond the 4 coarsest
                                                    // switch on over these steps (0 = off)
  int anneal_steps = kDefaultAnnealSteps;  // coarse-to-fine: deformation frequencies are switched on over
                                           // these steps (0 = off)
  // Steps of a start that fits the static field's density to the fitted face model's neutral head
  // before training (methods on the face-model prior; 0 = the uniform start; train/density_start.h).
  int density_start_steps = 0;
  double density_start_erosion = 0.04;     // head units the seeded head lies inside the fitted surface
  double density_start_log_density = 3.0;  // log-density the density start gives the inside of the head
  // Initialisations tried before training (1 = the seed's alone): each trains start_trial_steps
  // steps and the one with the lowest batch loss over the last quarter of them is trained from the
  // start (a field that is still transparent at step 100 can carve the face; docs/results/start_trials/).
  int start_trials = 1;
  int start_trial_steps = 100;
  int occupancy_warmup = 256;  // steps before the occupancy grid starts skipping empty space
  int occupancy_every = 16;    // steps between occupancy grid updates
  int checkpoint_every = 500;  // steps between checkpoints (0 = only at the end)
  int log_every = 50;          // steps between lines of train_log.jsonl
  int eval_every = 0;  // steps between held-out PSNR evaluations on observed-tier test frames (0 = off)
  int64_t seed = 0;    // root seed of every random draw
  int threads = 0;     // worker threads (0 = all cores)
  std::string on_nonfinite =
      "stop";  // a non-finite loss term or gradient: "stop" training, or "skip" the step

  void Bind(ConfigSchema& s);
  Status Validate() const;
  // The loss terms' weights and settings (the mask term only when the images have alpha).
  LossWeights Losses(bool has_alpha) const;
};

struct RunConfig {
  ModelConfig model;
  TrainConfig train;

  Status Validate() const;
  Json ToJson() const;
  // Reads a config file (following "parent" links); keys absent everywhere keep their defaults.
  static Result<RunConfig> FromFile(const std::filesystem::path& path);
  // `old_keys`: kRead for configs stored by earlier versions (checkpoints), whose model keys were
  // flat ("grid_levels"); a user's config naming one is an error that gives its current path.
  static Result<RunConfig> FromJson(const Json& json, const std::string& origin,
                                    ConfigSchema::OldKeys old_keys = ConfigSchema::OldKeys::kReject);
  // Applies one "section.key=value" override, e.g. "train.steps=500", "model.method=warp" or
  // "model.static_field.grid.finest_resolution=256"
  // (value parsed as JSON, or taken as a string when it is not valid JSON).
  Status ApplyOverride(const std::string& assignment);
  // Stable hash of the resolved config (for checkpoint headers).
  uint64_t Hash() const;
};

// The deformation encoding's coarse-to-fine parameter alpha after `step` steps (all frequencies
// on once step >= train.anneal_steps; model/coarse_to_fine.h). Training and every later render use
// the same value.
double DeformationAnnealing(const RunConfig& config, int64_t step);

// Per-level weights of the static field's hash grid after `step` steps (coarse-to-fine; all ones
// once step >= train.grid_anneal_steps, or when it is 0).
std::vector<float> GridLevelWeights(const RunConfig& config, int64_t step);

// Markdown for docs/config.md: one table per section.
std::string ConfigDocumentation();

}  // namespace icef
