// Depth targets from the fitted face model (train.lambda_depth_prior): for each chosen training
// pixel (train.depth_prior_region: the expression region of TrainingData's region pixels, the
// eyes alone, or the whole face), where the centre ray through it meets the fitted face model's
// surface at that frame's expression (the fit's shape and expression style, head_from_world
// carrying the ray into the head frame). The loss (model/losses.h, L_depth) pulls each such ray's
// compositing-weighted depth towards it, within a window and a reach along the ray
// (render/depth_loss.h). On by default for the face-model prior (lambda 30, window 0.01, reach
// 0.05, the expression region): on the validation identities it adds expression in every tier and
// brings the renders nearer the truth's identity (docs/results/near_tier_variants).
#pragma once

#include <array>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "icef/core/parallel.h"
#include "icef/data/dataset.h"
#include "icef/face/face_fit.h"
#include "icef/model/model_setup.h"
#include "icef/train/training_data.h"

namespace icef {

// The fitted face model's surface in the dataset's world frame at each training frame's expression:
// the procedural model of setup.face_fit (sphere-traced) or ICT-FaceKit of setup.ict_fit (its posed
// mesh's skin, mouth interior, teeth and eyes, intersected exactly: face/mesh_depth.h).
class FittedSurface {
 public:
  // expressions[k]: frame k's weights in the model's order (negative values act as 0). Errors: no
  // face-model fit in the setup.
  static Result<std::unique_ptr<FittedSurface>> Create(const ModelSetup& setup,
                                                       const std::vector<std::vector<float>>& expressions);
  virtual ~FittedSurface();
  // Ray parameters t of the centre rays of the camera's `pixels` (y * width + x) where they first
  // meet the surface at frame k's expression; NaN where they miss. Deterministic for any executor.
  virtual std::vector<float> Depths(const Camera& camera, int k, std::span<const int64_t> pixels,
                                    const Executor& executor) const = 0;
  // The model's 68 landmarks at frame k's expression, world frame.
  virtual std::array<Vec3f, 68> Landmarks(int k) const = 0;

  Vec3d pivot = Vec3d::Zero();  // the neutral landmarks' centre, world frame (unseen views turn about it)
  Vec3d up = Vec3d::UnitY();    // the head's up axis, world frame
};

// [data.num_pixels()] ray parameters t (world units along the pixel-centre ray), NaN outside
// `pixels` (global indices) and where the ray misses the fitted surface. Deterministic for any executor.
std::vector<float> FaceModelDepthTargets(const FittedSurface& surface, const TrainingData& data,
                                         const std::vector<int64_t>& pixels, const Executor& executor);

// Unseen views (train.depth_prior_views): each training frame's camera turned about the fitted
// face's centre by a yaw about the head's up axis and a pitch about the camera's right axis, each
// uniform within +-max_yaw_deg / +-max_pitch_deg, drawn from Rng(seed, "depth_prior_views", frame).
struct ViewRayOptions {
  int views_per_frame = 0;
  double max_yaw_deg = 20.0;
  double max_pitch_deg = 10.0;
  uint64_t seed = 0;
  // The view's pixels (train.depth_prior_view_region): the expression region ("expression", the
  // dilated hull of brows, eyes and mouth), the same hull without the mouth ("upper": brows and
  // eyes), or the expression region and the filled hull of all 68 landmarks ("face": nose, cheeks
  // and chin as well).
  enum class Region { kExpression, kUpper, kFace };
  Region region = Region::kExpression;
};

// "expression", "upper" or "face" (TrainConfig::Validate accepts no other).
ViewRayOptions::Region ViewRegionFromName(const std::string& name);

// The cameras of those views: [frame][view], intrinsics of the frame's camera.
std::vector<std::vector<Camera>> UnseenViewCameras(const FittedSurface& surface, const TrainingData& data,
                                                   const ViewRayOptions& options);

// The centre rays of the pixels of every unseen view that lie in the expression region of the
// fitted face model's own landmarks at that frame's expression (projected into the view;
// ExpressionRegion, dilated as the training frames' regions; options.region can drop the mouth's
// landmarks from it or add their filled hull, LandmarkHullRegion) and meet its surface there, each with
// the surface's ray parameter. L_depth on these reaches the geometry between the training views,
// which no image constrains. Deterministic for any executor.
std::vector<ViewRay> FaceModelViewRays(const FittedSurface& surface, const TrainingData& data,
                                       const ViewRayOptions& options, const Executor& executor);

// The training pixels of the eyes: each eye's 2D landmark hull (iBUG 36-41, 42-47) of each frame
// with landmarks, dilated as the expression region (DefaultRegionDilation). Global pixel indices.
std::vector<int64_t> EyePixels(const Dataset& dataset, const TrainingData& data);

// The training pixels of the face (train.depth_prior_region = "face"): the filled hull of all 68
// landmarks of each frame with landmarks (jaw line to brows: cheeks, nose and chin as well),
// united with the expression region (region_pixels(), dilated beyond the hull at the brows).
// Global pixel indices, ascending.
std::vector<int64_t> FacePixels(const Dataset& dataset, const TrainingData& data);

}  // namespace icef
