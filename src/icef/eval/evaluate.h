// The per-model evaluation protocol of docs/design.md §6 (`icef eval MODEL DATASET --out DIR`): every
// test frame is rendered at its camera and expression and compared with its ground truth (PSNR,
// SSIM over the full image composited on the background, LPIPS when weights are given), and its
// identity is measured with the face-descriptor network: the Euclidean distance and cosine between
// the descriptor of the render and that of the model's OWN neutral render (expression zero, same
// view) — the paper's drift measure — and, beside it, the distance to the ground-truth image.
// Results are aggregated per tier and written as metrics.json:
//   {"method", "frames": [{"file_path", "tier", "delta", "psnr", "ssim", "lpips", "id_cosine",
//    "id_distance", "id_distance_gt", ...extras}], "tiers": {"observed": {"count", "psnr", "ssim",
//    "lpips", "id_cosine", "id_distance", "id_distance_gt", "id_share_under_0_6", ...}, "near", ...},
//    "train_fit": {"count", "face_count", "face_psnr", "face_psnr_min", "psnr", "frames": [{"file_path",
//    "face_psnr", "face_pixels", "psnr", "render"}]}}
// with null wherever a value could not be computed (no LPIPS weights, no face found, ...).
// train_fit: every training frame rendered back at its own camera and expression, PSNR inside the
// face region of its landmarks and over the full image: a model that cannot reproduce its own
// training views is underfitting, whatever its batch PSNR says.
#pragma once

#include <array>
#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "icef/core/parallel.h"
#include "icef/core/progress.h"
#include "icef/data/dataset.h"
#include "icef/eval/face_identity.h"
#include "icef/eval/lpips.h"
#include "icef/io/json_util.h"
#include "icef/model/avatar_model.h"
#include "icef/model/render_image.h"

namespace icef::eval {

constexpr int kNumTiers = 4;
// observed, near, moderate, far (the order of every per-tier array).
const std::array<Tier, kNumTiers>& AllTiers();
inline int TierIndex(Tier tier) { return static_cast<int>(tier); }

// The metrics of one test frame.
struct FrameMetrics {
  std::string file_path;  // the frame's ground-truth image, relative to the dataset
  Tier tier = Tier::kObserved;
  double delta = 0;            // the dataset's delta of the frame
  std::optional<double> psnr;  // dB (null only when infinite: a pixel-perfect render)
  std::optional<double> ssim;
  std::optional<double> lpips;           // null without LPIPS weights
  std::optional<double> id_cosine;       // render vs the model's neutral render, same view
  std::optional<double> id_distance;     // Euclidean, same pair
  std::optional<double> id_distance_gt;  // render vs the ground-truth image of the frame
  // Ground truth vs the ground-truth neutral of the view, chips made exactly as for id_distance:
  // the drift a perfect model would show (null without a neutral image in the dataset).
  std::optional<double> id_distance_reference;
  // id_distance - id_distance_reference: drift beyond what the expression itself causes
  // (negative: the render moved less than the ground truth, i.e. under-expression).
  std::optional<double> id_excess;
  // Expression fidelity (eval/expression_fidelity.h), inside the frame's expression region; null
  // without ground-truth landmarks or a ground-truth neutral, and gain/corr null where the true
  // change is negligible (expr_true_rms below kNegligibleExpressionRms).
  std::optional<double> expr_gain;
  std::optional<double> expr_corr;
  std::optional<double> expr_gain_coarse;  // expr_gain at the features' scale (eval/expression_fidelity.h)
  std::optional<double> expr_true_rms;     // RMS of ground truth - ground-truth neutral in the region
  std::optional<double> region_psnr;       // PSNR inside the expression region, dB
  // Fine detail inside the face region (the hull of the frame's landmarks) relative to the truth's
  // (eval/metrics.h DetailRatio: 1 = as sharp, below 1 = blurred, above 1 = blocks or noise); null
  // without landmarks.
  std::optional<double> face_detail;
  // PSNR of the ground-truth neutral of the view against the ground truth: what a model that
  // renders no expression at all would score (null without a neutral image).
  std::optional<double> psnr_neutral_floor;
  int nearest_index = -1;  // the model's nearest training expression k
  double model_delta = 0;  // ||beta - beta_n|| as the model sees it
  double kappa = 1;        // confidence at that distance
  std::string landmarks;   // "dataset", "detector" or "none" (render chip)
  std::string
      neutral_landmarks;    // "dataset", "detector (ground truth)", "detector (render)", "frame", "none"
  std::string render_path;  // relative to the output directory (empty when not written)

  Json ToJson() const;
  // `where` names the object in errors, e.g. "run/metrics.json: frames[3]".
  static Result<FrameMetrics> FromJson(const Json& json, const std::string& where);
};

// Means over the frames of one tier. Identity means are over the frames where identity could be
// measured (id_count of them); a metric with no value in any frame is null.
struct TierMetrics {
  int count = 0;
  std::optional<double> psnr;
  std::optional<double> ssim;
  std::optional<double> lpips;
  std::optional<double> id_cosine;
  std::optional<double> id_distance;
  std::optional<double> id_distance_gt;
  std::optional<double> id_share_under_0_6;     // share of id_distance values under 0.6
  std::optional<double> id_distance_reference;  // mean ground-truth drift (see FrameMetrics)
  std::optional<double> id_excess;              // mean over frames with both distances
  std::optional<double> expr_gain;              // means over the frames with a non-negligible true change
  std::optional<double> expr_corr;
  std::optional<double> expr_gain_coarse;
  std::optional<double> region_psnr;
  std::optional<double> psnr_neutral_floor;
  std::optional<double> face_detail;  // mean over the frames with landmarks
  int expr_count = 0;                 // frames in the expr_gain mean
  int expr_negligible = 0;            // frames left out of it: negligible true change
  int id_count = 0;                   // frames with identity metrics
  double mean_delta = 0;              // mean dataset delta (0 when count is 0)

  Json ToJson() const;
  static Result<TierMetrics> FromJson(const Json& json, const std::string& where);
};

// The metrics a frame carries and a tier averages, written once: the JSON key (the same in a frame,
// a tier's means and the bench's tables), the frame's value, the tier's mean, and whether a metrics
// file must hold it (files from before the later metrics lack them). The frame's expr_true_rms and
// the tier's id_share_under_0_6 are each one's own.
struct MetricField {
  const char* key;
  std::optional<double> FrameMetrics::*frame;
  std::optional<double> TierMetrics::*tier;
  bool required;
};
std::span<const MetricField> MetricFields();

// Per-tier means of frame metrics (plain arithmetic means in frame order).
std::array<TierMetrics, kNumTiers> AggregateTiers(const std::vector<FrameMetrics>& frames);

// How well the model reproduces one of its own training frames, rendered back at the frame's camera
// and expression and compared with its image composited over the background.
struct TrainFrameFit {
  std::string file_path;  // the training image, relative to the dataset
  // PSNR inside the face region (FaceRegion of the frame's landmarks_2d, eval/expression_fidelity.h),
  // dB; null without landmarks (face_pixels 0) or when infinite (a pixel-perfect face).
  std::optional<double> face_psnr;
  int face_pixels = 0;  // pixels in the face region
  // Fine detail of the render in the face region relative to the truth's (eval/metrics.h
  // DetailRatio: 1 = as much pixel-scale detail, below 1 = blurred away, above = extra edges);
  // null without a face region.
  std::optional<double> face_detail;
  std::optional<double> psnr;  // full image, dB (null only when infinite)
  std::string render_path;     // relative to the output directory (empty when not written)

  Json ToJson() const;
  static Result<TrainFrameFit> FromJson(const Json& json, const std::string& where);
};

// The training-view fit: per-frame values and their means (over the frames with a value).
struct TrainingFit {
  std::vector<TrainFrameFit> frames;
  int count = 0;                    // training frames rendered (0: not measured, e.g. an old metrics.json)
  int face_count = 0;               // frames with a face_psnr (in its mean and minimum)
  std::optional<double> face_psnr;  // mean face-region PSNR, dB
  std::optional<double> face_psnr_min;  // the worst frame's
  std::optional<double> psnr;           // mean full-image PSNR, dB
  std::optional<double> face_detail;    // mean face-region detail ratio

  // Means and minimum of `frames`, in frame order.
  static TrainingFit Of(std::vector<TrainFrameFit> frames);
  Json ToJson() const;
  static Result<TrainingFit> FromJson(const Json& json, const std::string& where);
  // "training-view fit: face-region PSNR X dB (worst Y, N views), full image Z dB", or why not.
  std::string Summary() const;
};

// One model evaluated on one dataset: the content of metrics.json.
struct EvalResult {
  std::string method;
  double expression_scale = 1;  // every frame was rendered at expression_scale * beta
  std::vector<FrameMetrics> frames;
  std::array<TierMetrics, kNumTiers> tiers;
  TrainingFit train_fit;            // empty when not measured (metrics files from before it)
  bool identity_available = false;  // the face-descriptor network was loaded
  bool lpips_available = false;     // LPIPS weights were given
  int identity_missing = 0;         // frames whose identity could not be measured (no face)
  std::string identity_note;        // why identity is unavailable, when it is

  Json ToJson() const;
  static Result<EvalResult> FromJson(const Json& json, const std::string& origin);
  // The per-tier table printed by `icef eval`.
  std::string Table() const;
};

Status WriteMetricsFile(const std::filesystem::path& path, const EvalResult& result);
Result<EvalResult> ReadMetricsFile(const std::filesystem::path& path);

struct EvalOptions {
  // Output directory: renders go to out_dir/renders/ (paths in the result are relative to it);
  // empty: renders are not written.
  std::filesystem::path out_dir;
  // Also write each frame's model neutral render (renders/neutral_<view>.png).
  bool write_neutral_renders = true;
  // Each frame is rendered at expression_scale * beta (1 = as given; 0 = every frame at neutral,
  // the model that renders no expression at all, for checking the protocol).
  double expression_scale = 1;
  // Samples placed by the grid of the rendered expression (default) or by the training grid
  // (training expressions only, cut to the training visual hull): `icef eval --training-occupancy`.
  RenderOccupancyMode occupancy = RenderOccupancyMode::kExpression;
  // Training frames rendered back for EvalResult::train_fit: all of them up to this many, else this
  // many evenly spaced (few-shot datasets have 3-10; a NerFace video has thousands); 0: none.
  int train_fit_frames = 64;
  Status Validate() const;
  std::string ToString() const;
};

// The networks an evaluation may use; null members are unavailable (their metrics are null).
struct EvalNetworks {
  FaceIdentity* identity = nullptr;  // not thread-safe: frames are described one at a time
  const LpipsNet* lpips = nullptr;
  std::string identity_note;  // why `identity` is null (copied into the result)
};

// Evaluates `model` on the test frames of `dataset` (expression fidelity needs the frames' 2D
// landmarks and neutral images; the neutral's landmarks come from neutral_landmarks_2d, else from a
// dataset frame of the neutral image, else the frame's own hull stands alone). A frame without a
// tier gets one from its delta (the model's when the frame has none) and the dataset's tier
// thresholds. Then renders the training frames back (at expression_scale too; written as
// renders/fit_<stem>.png) for the training-view fit; their face region needs landmarks_2d. Errors:
// unreadable images, size mismatches, an expression dimension other than the model's.
// progress (may be null) counts test frames; its status names the training view being rendered.
Result<EvalResult> EvaluateModel(const AvatarModel& model, const Dataset& dataset, const EvalOptions& options,
                                 const EvalNetworks& networks, const Executor& executor,
                                 ProgressBar* progress);

}  // namespace icef::eval
