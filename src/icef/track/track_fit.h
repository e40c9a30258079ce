// The tracker's fit (docs/design.md §8): the face model fitted to the 2D landmarks of several images of
// one person at once. Identity (the shape scales) is shared; each image gets its own expression
// weights (in [0, max_expression]) and either its own head pose (photos: nothing is known of the
// cameras but their intrinsics) or, with known cameras (`icef track --keep-cameras`), one
// head_from_world similarity shared by all images. Robust nonlinear least squares (Ceres,
// Levenberg-Marquardt) on residuals in inter-ocular distances (IOD), with Gaussian priors that keep
// the shape near the average head and the expression weights small, and a second pass without
// the landmarks the first left far off (outliers).
//
// Conventions: cameras are OpenGL-style (looking down -Z, +Y up), landmarks are pixels with
// +0.5 centres (data/dataset.h), the head frame is face/face_model.h's.
#pragma once

#include <array>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "icef/core/status.h"
#include "icef/face/face_fit.h"
#include "icef/face/shape_params.h"
#include "icef/io/image.h"
#include "icef/math/camera.h"
#include "icef/math/types.h"
#include "icef/track/detector_landmarks.h"

namespace icef::track {

// The face model the tracker fits: the procedural head (face/face_model.h; landmarks, then the
// masks' outlines and the colours) or ICT-FaceKit (face/ict_model.h; landmarks only, the dataset in
// its 53 ARKit-named expressions, track/ict_track.h). Name and parser in photo_track.cc.
enum class TrackFaceModel { kProcedural, kIct };
const char* TrackFaceModelName(TrackFaceModel model);
std::optional<TrackFaceModel> ParseTrackFaceModel(const std::string& name);

// One image: its 68 detected landmarks and its camera (intrinsics; the pose only when known).
struct TrackFrame {
  std::vector<Vec2f> landmarks_2d;  // [68] pixels
  Intrinsics intrinsics;
  std::optional<Mat4d> world_from_cam;  // known camera pose (all frames or none)
  // Optional: points on the edge of the head's foreground mask (pixels, e.g. MaskEdgePoints of a
  // GrabCut mask). Each adds a silhouette residual: the fitted surface's closest approach to the
  // point's ray, which is 0 where the ray grazes the head.
  std::vector<Vec2f> silhouette;
  // Optional: the image itself (RGB or RGBA, the pixels the landmarks and intrinsics refer to; not
  // owned, it must outlive FitTrack). When every frame has one, a photometric refit follows the
  // landmark fit (TrackFitOptions::photometric_weight; track/photometric.h).
  const Image* photo = nullptr;
};

// The defaults were chosen on synthetic photos of validation identities 101-106 (scripts/track_eval.py).
struct TrackFitOptions {
  // Landmark noise the priors are balanced against (IOD), for either detector. dlib's averaged
  // landmarks scatter by about this much around detector_landmarks.inc (2.5 px at 360x480). The
  // face mesh's scatter less (1.9 px), and on synthetic photos of validation identities 101-112 a
  // looser 0.1 scored better (docs/results/track_eval), but synthetic heads are drawn from the
  // shape prior itself: on real photos 0.1 left the fitted head visibly off the face (landmark RMS
  // 0.06-0.10 IOD on the astronaut and Grace Hopper, against 0.035-0.042 at 0.05).
  double landmark_sigma_iod = 0.05;
  double shape_prior_sigma = 0.1;  // std of each shape scale around 1
  // Bounds of every shape scale (they keep the head buildable). A silhouette refit that ends with
  // one on a bound has degenerated (no head seen so far lies beyond 0.65-1.35): the landmarks' fit
  // is kept (TrackFit::silhouettes).
  double shape_min = 0.5;
  double shape_max = 1.6;
  double expression_prior_sigma = 0.3;  // std of each expression weight around 0 (neutral)
  // A Laplace (L1) prior on the weights besides the Gaussian one, cost sum(weights) / this scale
  // (0: none): a photo shows few expressions at once, and this prior leaves the others at exactly 0.
  double expression_prior_laplace = 0;
  double max_expression = 1.5;   // upper bound of the weights (lower bound 0)
  double jaw_line_weight = 0.5;  // weight of landmarks 0-16: the detector follows the silhouette there
  int max_iterations = 80;       // Levenberg-Marquardt iterations per pass
  double outlier_iod = 0.1;      // second pass: drop landmarks farther than this (IOD) and 3x the median
  bool dlib_convention =
      true;  // the landmarks are a detector's: fit the model's landmarks moved by its offsets
  LandmarkDetector detector =
      LandmarkDetector::kMesh;  // whose (DetectorLandmarkOffsets), with dlib_convention
  // Silhouette points (TrackFrame::silhouette): their noise (IOD). A frame's points weigh together
  // as much as 68 landmarks at this noise would, however many there are.
  double silhouette_sigma_iod = 0.03;
  // Silhouette points the landmark fit's head does not explain are left out: farther than this from
  // its surface (IOD), or, with silhouette_face_only, touching it above the brows or below the chin.
  double silhouette_max_gap_iod = 0.15;
  bool silhouette_face_only = true;
  // The photometric refit (TrackFrame::photo): points of the neutral face carried into every image
  // by the fitted warp and pose must find the same colour there. A frame's colour residuals weigh
  // together this many times as much as its 68 landmarks (0: no refit).
  double photometric_weight = 16;
  double photometric_sigma =
      0.05;  // colour noise (colours in [0, 1]); also where the Cauchy loss discounts a point
  // Known cameras: the refit keeps the shared similarity as the landmark and outline fit left it and
  // moves the expressions only (with outlines the similarity is placed; colours then pull it).
  bool photometric_hold_similarity = false;
  double photometric_expression_prior_sigma = 0.2;    // the refit's expression_prior_sigma
  double photometric_expression_prior_laplace = 0.3;  // the refit's expression_prior_laplace
  int photometric_points = 400;                       // points on the neutral face (track/photometric.h)
  // The images are blurred by a Gaussian of this standard deviation (IOD), coarse then fine: each
  // blur is one Levenberg-Marquardt solve started from the last.
  double photometric_blur_coarse_iod = 0.1;
  double photometric_blur_fine_iod = 0.04;
  // After the refit, if the images' colours still disagree by more than this RMS (the upper median
  // over the images, after each one's exposure gain), the refit is dropped and the landmark fit
  // stands: the photos then do not show one consistently lit face (synthetic photos: medians
  // 0.01-0.02; the two webcam frames of opencv-doc, lit differently and drawn on: 0.09).
  double photometric_max_rms = 0.06;
  // The subject's expression style (face/expression_style.h) the weights are read in: generic for
  // photos; `--keep-cameras` with the face model's own landmarks fits it (track/dataset_retrack.h).
  face::ExpressionStyle style = face::ExpressionStyle::Generic();

  Status Validate() const;
  std::string ToString() const;
};

struct TrackedFrame {
  Mat4d cam_from_head = Mat4d::Identity();  // rigid: head frame -> camera frame
  std::vector<float> expression;            // [face::kNumExpressions], face-model order
  // The fitted model's own landmarks at that expression (head frame; the face model's convention,
  // which face/face_fit.h expects, whatever convention the fit used).
  std::array<Vec3f, 68> landmarks_head{};
  std::vector<Vec2f> projected;          // [68] the fitted landmarks (the fit's convention) in the image
  double rms_iod = 0;                    // landmark residual of this frame (inliers)
  double max_iod = 0;                    // its largest landmark residual (all landmarks)
  int landmarks_used = 0;                // inliers
  double photometric_rms = 0;            // colour residual of this frame's visible face points (0: no refit)
  int photometric_used = 0;              // those points
  double silhouette_rms_iod = 0;         // silhouette gap of the inlier silhouette points (0: none given)
  int silhouette_used = 0;               // inlier silhouette points
  std::vector<Vec2f> silhouette_points;  // those points (pixels), for overlays
  std::string ToString() const;
  // The head's rotation relative to the camera, degrees: yaw (positive turns the face toward the
  // subject's left, the image's right), pitch (positive lifts the chin), roll (positive turns the
  // head counter-clockwise in the image); cam_from_head = Rz(roll) Rx(-pitch) Ry(yaw).
  Vec3d YawPitchRollDeg() const;
};

struct TrackFit {
  face::ShapeParams shape;
  // The ICT tracker (track/ict_track.h) only: its identity coefficients (empty for the procedural model).
  std::vector<float> ict_identity;
  // Known cameras only: dataset world -> head frame (photos: each frame's cam_from_head instead).
  std::optional<face::Similarity> head_from_world;
  std::vector<TrackedFrame> frames;
  double rms_iod = 0;  // over all frames' inliers
  double max_iod = 0;
  int iterations = 0;
  // The photometric refit: "off" (no images, one image or weight 0), "used", or "not used: ..." with
  // the reason (TrackFitOptions::photometric_max_rms); each frame's photometric_rms says how far
  // its colours agreed either way.
  std::string photometric = "off";
  // The silhouette refit: "off" (no silhouette points), "used", or "not used: ..." when it drove a
  // shape scale to its bound (a degenerate head) and the landmarks' fit was kept instead.
  std::string silhouettes = "off";
  std::string BriefReport() const;
  std::string ToString() const { return BriefReport(); }
};

// Errors: no frames; a frame without 68 finite landmarks, with coinciding eyes or invalid
// intrinsics; known poses on some frames only; invalid options; a solve that fails.
Result<TrackFit> FitTrack(std::span<const TrackFrame> frames, const TrackFitOptions& options = {});

}  // namespace icef::track
