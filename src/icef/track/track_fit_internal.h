// The tracker's fit (track_fit.h) inside: what track_fit.cc's landmark and silhouette fits and
// photometric_refit.cc's photometric refit share. Not for use outside src/icef/track.
#pragma once

#include <ceres/ceres.h>

#include <array>
#include <deque>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "icef/core/status.h"
#include "icef/face/expression.h"
#include "icef/face/face_fit.h"
#include "icef/face/face_model.h"
#include "icef/face/shape_params.h"
#include "icef/math/camera.h"
#include "icef/math/types.h"
#include "icef/track/track_fit.h"

namespace icef::track::internal {

inline constexpr int kNumLandmarks = 68;
inline constexpr int kExpr = face::kNumExpressions;
inline constexpr int kShape = face::ShapeParams::kCount;
inline constexpr int kPhotoPose =
    6;  // angle-axis on top of the frame's initial rotation [3], translation [3]
inline constexpr int kSharedPose =
    7;  // angle-axis on top of the initial rotation [3], translation [3], log scale [1]

// Face models by shape: Ceres perturbs the shape block the same way for every frame, so a small
// cache of recent shapes saves rebuilding the head (its landmarks come from marching its SDF).
class ModelCache {
 public:
  // Every model of the cache has this expression style (TrackFitOptions::style); set it before use.
  void SetStyle(const face::ExpressionStyle& style) {
    style_ = style;
    entries_.clear();
  }
  const face::FaceModel& For(const double* shape) {
    std::array<float, kShape> key;
    for (int i = 0; i < kShape; ++i) key[i] = static_cast<float>(shape[i]);
    for (const auto& [k, model] : entries_)
      if (k == key) return *model;
    if (entries_.size() >= 64) entries_.pop_front();
    entries_.emplace_back(key, std::make_unique<face::FaceModel>(face::ShapeParams::FromArray(key), style_));
    return *entries_.back().second;
  }

 private:
  face::ExpressionStyle style_;
  std::deque<std::pair<std::array<float, kShape>, std::unique_ptr<face::FaceModel>>> entries_;
};

// Everything a frame's residual needs besides the parameters.
struct FrameProblem {
  const TrackFrame* frame = nullptr;
  double iod_px = 1;
  Mat3d base_rotation = Mat3d::Identity();  // photos: the initial head rotation
  std::array<double, kNumLandmarks> weight{};
  std::vector<double> silhouette_weight;  // [frame->silhouette.size()]: 1, or 0 once an outlier
};

struct Shared {
  ModelCache cache;
  face::Similarity base;  // known cameras: the initial head_from_world
  double max_expression = 1.5;
  bool known_cameras = false;
  bool dlib_convention = true;  // fit the model's landmarks moved by DetectorLandmarkOffsets(detector)
  LandmarkDetector detector = LandmarkDetector::kDlib;
  double landmark_sigma = 0.06;    // TrackFitOptions::landmark_sigma_iod
  double silhouette_sigma = 0.03;  // TrackFitOptions::silhouette_sigma_iod
  double iod_head = 1;             // the average head's inter-ocular distance (head units)
  bool use_silhouettes = false;    // add the frames' silhouette residuals (the second stage)
};

struct Solution {
  std::array<double, kShape> shape;
  std::vector<std::array<double, kExpr>> expression;
  std::vector<std::vector<double>> pose;  // photos: per frame [6]; known cameras: [1][7]
  int iterations = 0;
  std::vector<double> photometric_rms;  // per frame, after the photometric refit (empty: none)
  std::vector<int> photometric_used;
  std::string photometric_note;  // TrackFit::photometric
  std::string silhouette_note;   // TrackFit::silhouettes
};

// The weights clamped to [0, max_expression], as the face model takes them.
std::vector<float> ClampedExpression(const double* e, double max_expression);
// The camera seeing the head frame (photos) or the dataset world (known cameras) for a pose.
Camera FrameCamera(const FrameProblem& fp, const Shared& shared, const double* pose);
// Known cameras: the head_from_world similarity of the shared pose block.
face::Similarity SharedSimilarity(const Shared& shared, const double* pose);
// Frame k's pose block.
const double* PoseOf(const Solution& s, const Shared& shared, int k);
// The landmark (and silhouette) residuals of the frames `which`, their priors and bounds.
void AddLandmarkBlocks(ceres::Problem& cp, std::vector<FrameProblem>& problems, const std::vector<int>& which,
                       Shared& shared, const TrackFitOptions& options, bool fit_shape, bool fit_pose,
                       Solution* s);
// One Levenberg-Marquardt solve of the problem (single-threaded: deterministic).
Status RunSolver(ceres::Problem& cp, const TrackFitOptions& options, Solution* s);

// The photometric refit (photometric_refit.cc): after the landmark fit, every frame's expression
// and pose refined on its image (TrackFrame::photo); the shape held. Leaves *s at the landmark fit
// when the images' colours disagree (TrackFitOptions::photometric_max_rms); either way sets
// s->photometric_note and the per-frame photometric figures.
Status PhotometricRefit(std::vector<FrameProblem>& problems, Shared& shared, const TrackFitOptions& options,
                        Solution* s);

}  // namespace icef::track::internal
