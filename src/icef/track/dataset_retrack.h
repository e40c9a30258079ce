// `icef track DATASET --keep-cameras --out NEW` (docs/design.md §8): an existing dataset (NerFace's
// 76-D Face2Face vectors, instant-ngp, any other expression space) re-expressed in the face model's
// expression space, so the prior-guided methods apply to it. Its cameras, images, aabb, background
// and test tiers stay; the face model is fitted to the 2D landmarks of every frame (dlib's,
// detected anew, by default; or the dataset's own, in a convention the caller names) with one
// head_from_world similarity shared by all frames (track_fit.h), and to the outlines of the frames'
// alpha masks where they have them; each frame gets the fitted
// expression weights, the landmarks the fit used and the fitted model's 3D landmarks (world frame).
#pragma once

#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "icef/core/parallel.h"
#include "icef/core/status.h"
#include "icef/data/dataset.h"
#include "icef/face/ict_fit.h"
#include "icef/io/image.h"
#include "icef/io/json_util.h"
#include "icef/track/track_fit.h"

namespace icef::track {

// Whose 2D landmarks the fit uses.
enum class RetrackLandmarks {
  kDetect,        // dlib's, detected anew in every frame (the default)
  kDatasetDlib,   // the dataset's own landmarks_2d, in dlib's convention (icef landmarks, icef track)
  kDatasetModel,  // the dataset's own landmarks_2d, in the face model's convention (icef synth)
};
const char* RetrackLandmarksName(RetrackLandmarks landmarks);
std::optional<RetrackLandmarks> ParseRetrackLandmarks(const std::string& name);  // "detect", "dlib", "model"

// Datasets with more frames than this are fitted on their landmarks only: the photometric refit
// (track_fit.h) solves all frames at once, with every image in memory.
inline constexpr int kMaxPhotometricFrames = 64;

// At most this many frames add their outlines (RetrackOptions::silhouette_points), spread over the
// sequence (SpreadFrames): they place the similarity all frames share, and each costs the solve a
// few hundred residuals; the other frames keep their landmarks.
inline constexpr int kMaxSilhouetteFrames = 64;

// Indices into n frames: all of them up to `max`, else `max` spread evenly from the first to the last.
std::vector<int> SpreadFrames(int n, int max);

// The photometric refit's default weight for a landmark source: on (TrackFitOptions' 16) for dlib's
// landmarks, whose scatter it reads past; off for the face model's own, which are exact and which it
// only pulls away from (docs/tracking.md: the round trips of validation identities 101-103).
double RetrackPhotometricWeight(RetrackLandmarks landmarks);

// The photometric refit's default weight when outlines place the similarity (RetrackOptions::
// silhouette_points): the similarity is then held in the refit and the colours read the expressions
// only, at this weight (chosen on validation identities 101-103; docs/tracking.md).
inline constexpr double kRetrackPhotometricWeightWithOutlines = 64;

// The silhouette term's default for a landmark source, as the refit's: 200 mask-edge points per frame
// for dlib's landmarks, none with the face model's own (exact: they place the head already).
int RetrackSilhouettePoints(RetrackLandmarks landmarks);

// The detected landmarks' noise (IOD) with every camera known: looser than photo tracking's 0.05.
// The similarity is shared by every frame and the outlines of many views place it, so the
// landmarks weigh in each frame's expression against the refit's colours and the priors. Round
// trips of validation identities 101-103 (face mesh, icef-prior trained on the result), mean PSNR
// observed / near / moderate / far: 30.87 / 30.94 / 30.84 / 29.99 dB at 0.05, 31.23 / 31.21 /
// 31.19 / 30.30 at 0.1 (docs/results/track_roundtrip/mesh.json).
constexpr double kRetrackLandmarkSigmaIod = 0.1;
// The face model's own landmarks' noise (IOD): they are exact, and the subject's fitted style
// matches them to 0.0013-0.0015 IOD, so the priors need only break ties. Round trips of
// validation identities 101 and 102 (icef-prior trained on the result), expression RMS of the
// training / test frames: 0.060 / 0.158 and 0.079 / 0.156 at 0.02 (the value before 2026-11-28),
// 0.025 / 0.131 and 0.052 / 0.094 at 0.005, 0.021 / 0.127 and 0.047 / 0.088 at 0.002; the
// trained models' expr_gain within 0.023 of the originals' in every tier at 0.002
// (docs/results/track_roundtrip/landmark_sigma.json).
constexpr double kRetrackModelLandmarkSigmaIod = 0.002;
// The landmark noise a landmark source's fit assumes: kRetrackLandmarkSigmaIod for a detector's,
// kRetrackModelLandmarkSigmaIod for the face model's own.
double RetrackLandmarkSigma(RetrackLandmarks landmarks);

struct RetrackOptions {
  RetrackLandmarks landmarks = RetrackLandmarks::kDetect;
  bool skip_bad = false;  // drop frames without landmarks (no face found) instead of stopping
  // Frames whose image has an alpha channel (a foreground mask: icef synth, icef track), or, RGB, whose
  // dataset has a background image (NerFace; head_mask.h's BackgroundDifferenceMask), add this many
  // points of the mask's edge to the fit (TrackFrame::silhouette; which part of the outline:
  // fit.silhouette_face_only); 0: landmarks only; < 0 (the default): the landmark source's default,
  // RetrackSilhouettePoints(landmarks). With every camera known, the outlines place the head where
  // dlib's landmarks, biased differently in each view, leave it a few degrees off.
  int silhouette_points = -1;
  std::filesystem::path predictor_path;  // dlib's shape predictor; empty: the Debian default
  // With landmarks kDetect: whose 68 landmarks are detected (dlib's, or the face mesh's placed by
  // dlib's face); the fit uses that detector's offsets (fit.detector is set to match).
  LandmarkDetector detector = LandmarkDetector::kMesh;
  // fit.photometric_weight < 0 (the default): the landmark source's default,
  // RetrackPhotometricWeight(landmarks). fit.landmark_sigma_iod < 0 (the default): the landmark
  // source's default, RetrackLandmarkSigma(landmarks).
  TrackFitOptions fit = [] {
    TrackFitOptions o;
    o.photometric_weight = -1;
    o.landmark_sigma_iod = -1;
    return o;
  }();
  // With landmarks kDatasetModel (exact): read the subject's expression style off them
  // (face/face_fit.h, fit_style, the test that trainer's fit uses to keep it), then read the weights
  // again in that style, and write the styled model's landmarks, so that the trainer's face-model
  // fit finds the style again. False: every weight in the generic style (dlib's and the face mesh's
  // landmarks always are: they are too coarse to tell a style from a weight).
  bool fit_style = true;
  // kIct: ICT-FaceKit fitted to the landmarks with the cameras held (track/ict_track.h: one head
  // pose among them; silhouettes, colours and style are not used), the dataset written in its 53
  // ARKit-named expressions with the fitted mesh's landmarks_3d.
  TrackFaceModel face_model = TrackFaceModel::kProcedural;
  face::IctFitOptions ict_fit = face::IctFitOptions::ForPhotos();  // with face_model kIct
  Status Validate() const;
  std::string ToString() const;
};

struct RetrackResult {
  Dataset dataset;                   // the source dataset re-expressed (root: the source's)
  std::vector<std::string> skipped;  // "train[3] images/...: no face found"
  // Frames where the detector found no face and the dataset's own landmarks_2d were fitted instead.
  std::vector<std::string> fallbacks;
  std::vector<std::string> frame_names;  // per fitted frame, in fit order: "train[0] images/..."
  int outlined_frames = 0;               // frames that added their outlines
  double photometric_weight = 0;         // the refit's weight as used (0: off)
  bool similarity_held = false;          // the refit kept the similarity the outlines placed
  // RetrackOptions::fit_style with the face model's landmarks: the style fit (its style is the one
  // the weights were read in unless style_rejected).
  std::optional<face::FaceFit> style_fit;
  TrackFit fit;
};

// Errors: a frame without a face (unless skip_bad) naming it, a fit that fails.
Result<RetrackResult> RetrackDataset(const Dataset& source, const RetrackOptions& options,
                                     const Executor& executor,
                                     const std::function<void(const std::string&)>& log = nullptr);

// Per frame: name, landmark residual, expression; plus the similarity and the shape.
Json RetrackReportJson(const RetrackResult& result);

// Writes the re-expressed dataset into out_dir (which must not exist or be empty): the transforms
// files, a copy of every image they reference, track/report.json and `extra_images` (paths relative
// to out_dir, e.g. overlays). Built in a temporary sibling directory and renamed into place.
Status WriteRetrackedDataset(const RetrackResult& result, const std::filesystem::path& out_dir,
                             const std::vector<std::pair<std::string, Image>>& extra_images = {});

}  // namespace icef::track
