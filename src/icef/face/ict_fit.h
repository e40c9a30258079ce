// ICT-FaceKit (face/ict_model.h) fitted to the 68 landmarks of several photos of one person: the
// building block of a tracker on the ICT model. Identity coefficients are shared by all photos;
// each photo gets its own head pose and its own 53 expression weights in [0, 1]. Nonlinear least
// squares (Ceres, Levenberg-Marquardt, analytic Jacobians) on landmark reprojection errors in
// inter-ocular distances (IOD), with a ridge prior on the identity, a sparsity prior on the
// expressions and a coupling of the _L/_R halves of each expression pair. A pose-only solve on the
// mean head starts it; then everything is solved jointly.
//
// Conventions: cameras are math/camera.h's (OpenGL-style: looking down -Z, +Y up; image v points
// down, pixel centres at +0.5; signed focal lengths); the head frame and its units (cm) are
// face/ict_model.h's; landmarks are the iBUG 68 in the model's order (landmark_vertices()).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "icef/core/status.h"
#include "icef/face/face_fit.h"
#include "icef/face/ict_model.h"
#include "icef/math/camera.h"
#include "icef/math/types.h"

namespace icef::face {

// One photo: its camera intrinsics and its observed landmarks.
struct IctObservation {
  Intrinsics intrinsics;
  std::vector<Vec2f> landmarks;  // [68] pixels, iBUG order
  // [68] or empty (all 1): each landmark's weight, multiplying its residual; 0 = missing (its
  // position is then ignored and may be anything, NaN included).
  std::vector<float> weights;
  // The camera, when known: camera-from-world, rigid, in the world's units (math/camera.h's camera
  // frame). Either every photo has one or none does. With them, the fit solves one head pose for
  // all photos, the similarity head_from_world (IctFit::head_from_world), instead of a pose per photo:
  // the dataset's cameras stay as they are and the head is placed among them.
  std::optional<Mat4d> cam_from_world;
};

struct IctFitOptions {
  int num_identity = 40;              // identity modes fitted (the first ones); the others stay 0
  double landmark_sigma_iod = 0.03;   // landmark noise (IOD) the priors are balanced against
  double jaw_line_weight = 0.5;       // weight of landmarks 0-16: the outline slides on the cheek
  double identity_prior_sigma = 1;    // std of each identity coefficient (the model's are ~N(0, 1))
  double expression_prior_sigma = 1;  // std of each expression weight around 0 (Gaussian, L2)
  // Laplace (L1) prior on the weights, cost sum(weights) / this scale, smoothed below 0.02 (0: none):
  // a photo shows few expressions at once, and this prior leaves more of the others at 0.
  double expression_prior_laplace = 0;
  // Std of beta_L - beta_R for every _L/_R pair (mouthSmile_L/R, eyeBlink_L/R, ...; not the gaze
  // pairs eyeLook*_L/R, which move in opposite halves); infinity: no coupling.
  double symmetry_sigma = 0.3;
  int rigid_iterations = 30;          // Levenberg-Marquardt iterations of the pose-only start
  int max_iterations = 100;           // Levenberg-Marquardt iterations of the joint solve
  double function_tolerance = 1e-10;  // Ceres' relative cost change that ends a solve
  bool check_gradients = false;       // Ceres checks every Jacobian against finite differences (slow: tests)

  Status Validate() const;
  std::string ToString() const;

  // The settings for real photos and video frames (the tracker's and icef train's), chosen on the
  // validation media (smirk-dafoe, 24 frames; docs/tracking.md): all 100 identity modes with a
  // looser identity prior (sigma 3) and a sparsity prior (laplace 0.2). Against the defaults above
  // (40 modes, sigma 1, no sparsity): landmark RMS 0.040 instead of 0.056 IOD, and the expressions
  // sparse (weights summed 1.5 instead of 10.5 per frame; the defaults held cheekPuff near 1 in
  // every frame, the face's shape read as an expression).
  static IctFitOptions ForPhotos();
};

struct IctPhotoFit {
  Mat4d cam_from_head = Mat4d::Identity();  // rigid: head frame (cm) -> camera frame (cm)
  std::vector<float> expression;            // [53] in [0, 1], the model's order
  std::vector<Vec2f> projected;             // [68] the fitted landmarks in the image (pixels)
  // The error unit: the distance between the centres of the eyes' landmarks (36-41, 42-47) present;
  // for a photo with no landmark on one eye, the neutral head's IOD at the initial pose's depth.
  double iod_px = 0;
  double rms_iod = 0;      // landmark RMS over the landmarks used (unweighted)
  double max_iod = 0;      // their largest error
  int landmarks_used = 0;  // weight > 0 (and a vertex in the model)
  std::string ToString() const;
};

struct IctFit {
  std::vector<float> identity;      // [num_identity] coefficients of the first modes (~N(0, 1))
  std::vector<IctPhotoFit> photos;  // one per observation, in order
  // With known cameras (IctObservation::cam_from_world): the world frame -> head frame (cm) the fit
  // placed the head at; each photo's cam_from_head is then its camera composed with it, in cm.
  std::optional<Similarity> head_from_world;
  double rms_iod = 0;  // over all photos' landmarks used
  double max_iod = 0;
  int iterations = 0;     // Levenberg-Marquardt iterations, both stages
  double final_cost = 0;  // Ceres' cost (half the sum of squared scaled residuals)
  std::string BriefReport() const;
  std::string ToString() const;
};

// Errors (one line naming the photo): invalid options; no observations; known cameras for some
// photos but not all, or known cameras that do not determine the scale (fewer than two camera
// positions, or none not on one line with the head); a photo with invalid
// intrinsics, without 68 landmarks (or weights), with a negative or non-finite weight, a
// non-finite landmark of weight > 0, or fewer than 6 landmarks of weight > 0; a solve that fails.
Result<IctFit> FitIctToLandmarks(const face::IctModel& model, const std::vector<IctObservation>& photos,
                                 const IctFitOptions& options = {});

}  // namespace icef::face
