// Self-reenactment on real media (docs/design.md §9, `icef bench --real`): a model trained on K
// tracked frames of a real person renders every held-out frame at its tracked camera with its
// tracked expression, and the render is compared with the real photo. There is no ground truth
// of the avatar itself, so the measures are against the photo:
// - face_psnr / face_ssim: inside the face (the filled hull of the frame's 68 landmarks);
//   head_psnr / head_ssim: inside the head mask (the frame's alpha > 0.5);
// - lpips over the whole image (with weights), id_distance: face descriptors of render and photo;
// - real_expr_gain: the same camera is rendered a second time with the nearest training frame's
//   expression; over the mouth/eye/brow region, (err_nearest - err_tracked) / err_nearest with err
//   the squared error against the photo: 1 = the tracked expression closes all of the gap, 0 = it
//   changes nothing, below 0 = it makes the render worse;
// - face_psnr_nearest: the face PSNR of that nearest-expression render (what an avatar that does
//   not move scores);
// - track_rms_iod: the held-out frame's tracking residual (its fitted 3D landmarks projected by the
//   frame's camera against its 2D landmarks, RMS over the 51 inner landmarks in inter-ocular
//   distances; the jaw outline is view-dependent and left out), so that a badly tracked frame is
//   told apart from a bad avatar.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "icef/core/parallel.h"
#include "icef/core/progress.h"
#include "icef/data/dataset.h"
#include "icef/eval/evaluate.h"
#include "icef/io/image.h"
#include "icef/io/json_util.h"
#include "icef/model/avatar_model.h"

namespace icef::eval {

// The measures of one held-out real frame (null where a value cannot be computed).
struct RealFrameMetrics {
  std::string file_path;            // the photo, relative to the dataset
  double delta = 0;                 // distance of its expression to the nearest training frame's
  int nearest_train = -1;           // that training frame
  std::optional<double> face_psnr;  // dB
  std::optional<double> face_ssim;
  std::optional<double> head_psnr;  // dB
  std::optional<double> head_ssim;
  std::optional<double> lpips;
  std::optional<double> id_distance;  // render vs photo
  std::optional<double> real_expr_gain;
  std::optional<double> face_psnr_nearest;  // the nearest-expression render's face PSNR, dB
  std::optional<double> track_rms_iod;
  std::string render_path;  // renders, relative to the output directory ("" = not written)
  std::string nearest_path;

  Json ToJson() const;
  static Result<RealFrameMetrics> FromJson(const Json& json, const std::string& where);
};

// Means over frames (each over the frames that have the value; null where none has).
struct RealMeans {
  int count = 0;
  std::optional<double> face_psnr, face_ssim, head_psnr, head_ssim, lpips, id_distance, real_expr_gain,
      face_psnr_nearest, track_rms_iod;
  static RealMeans Of(const std::vector<RealFrameMetrics>& frames);
  Json ToJson() const;
  static Result<RealMeans> FromJson(const Json& json, const std::string& where);
};

struct RealEvalResult {
  std::string method;
  std::vector<RealFrameMetrics> frames;
  RealMeans means;
  bool identity_available = false;
  bool lpips_available = false;
  Json ToJson() const;
  static Result<RealEvalResult> FromJson(const Json& json, const std::string& where);
};

// (err_nearest - err_tracked) / err_nearest, err the sum of squared RGB differences to `photo`
// over the pixels where region > 0.5; null when the region is empty or err_nearest is 0.
// A render equal to the photo scores 1; a render equal to the nearest-expression render scores 0.
std::optional<double> RealExpressionGain(const Image& photo, const Image& tracked, const Image& nearest,
                                         const Image& region);

// The frame's tracking residual (see above); null without both landmark sets.
std::optional<double> TrackingResidualIod(const Frame& frame);

// The training frame whose expression is nearest to `expression` (L2), and the distance.
std::pair<int, double> NearestTrainingExpression(const Dataset& dataset,
                                                 const std::vector<float>& expression);

struct RealEvalOptions {
  std::filesystem::path out_dir;  // renders go to out_dir/renders/ ("" = none written)
  Status Validate() const { return Status::Ok(); }
};

// Evaluates `model` on the held-out frames of a tracked real dataset (frames need landmarks_2d;
// landmarks_3d for the tracking residual). progress (may be null) counts test frames.
Result<RealEvalResult> EvaluateReal(const AvatarModel& model, const Dataset& dataset,
                                    const RealEvalOptions& options, const EvalNetworks& networks,
                                    const Executor& executor, ProgressBar* progress);

}  // namespace icef::eval
