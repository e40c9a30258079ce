// `icef track PHOTOS... --out DATASET` (docs/design.md §8): a dataset in the §4 format from a handful of
// photos of one person. Per photo: exactly one face and its 68 landmarks (dlib); one joint fit of
// the face model (track_fit.h: shared identity, per-photo head pose and expression); a square crop
// around the fitted head resampled to the dataset's resolution; a foreground mask (head_mask.h,
// with the person segmentation of person_segmentation.h).
// The dataset's world frame is the fitted head frame: transform_matrix = camera-to-head,
// expression_names = the face model's, aabb around the head.
//
// TrackPhotos works in memory and writes nothing, so bad input (no face, two faces, an unreadable
// file, too few photos) stops before anything is on disk; WriteTrackedDataset writes the result.
#pragma once

#include <filesystem>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "icef/core/parallel.h"
#include "icef/core/status.h"
#include "icef/data/dataset.h"
#include "icef/face/ict_fit.h"
#include "icef/io/image.h"
#include "icef/io/json_util.h"
#include "icef/landmarks/face_landmark_detector.h"
#include "icef/landmarks/face_mesh.h"
#include "icef/track/head_mask.h"
#include "icef/track/person_segmentation.h"
#include "icef/track/photo_crop.h"
#include "icef/track/track_fit.h"

namespace icef::track {

struct TrackOptions {
  TrackFaceModel face_model = TrackFaceModel::kProcedural;
  int resolution = 256;         // side of the square dataset images
  std::optional<double> focal;  // focal length in pixels of the photos (else EXIF, else the default)
  // Without num_train: the last num_test photos become test frames. With num_train > 0: that many
  // training frames are chosen for coverage of head pose and expression (data/frame_coverage.h),
  // and num_test of the others (spread evenly in input order; 0 = all of them) are held out; the
  // rest are left out of the dataset.
  int num_test = 0;
  int num_train = 0;
  bool allow_blink = false;     // with num_train: a frame with an eye closed may be a training frame
  bool skip_bad = false;        // skip photos without exactly one face instead of stopping
  double crop_margin = 1.15;    // crop side / the head box's projected extent
  int silhouette_points = 200;  // refit with this many mask edge points per photo (0: landmarks only)
  // The dataset's alpha: GrabCut alone, GrabCut with the person segmentation's confident background
  // as sure background (default), or the person segmentation alone (PersonMask: shoulders included).
  enum class Segmentation { kNone, kSelfie, kSelfieOnly };
  Segmentation segmentation = Segmentation::kSelfie;
  TrackFitOptions fit;                                             // the procedural model's fit
  face::IctFitOptions ict_fit = face::IctFitOptions::ForPhotos();  // ICT's
  HeadMaskOptions mask;

  Status Validate() const;
  std::string ToString() const;
};

// Where a photo's focal length came from.
enum class FocalSource { kFlag, kExif, kDefault };
const char* FocalSourceName(FocalSource source);

// One image to track: a photo file, or a frame already decoded (a video's).
struct TrackInput {
  std::filesystem::path source;  // the photo, or the video the frame came from
  std::string name;              // how logs and the report name it (empty: the source's file name)
  std::optional<Image> image;    // the decoded frame (upright RGB); empty: read `source`
  std::optional<double> time_s;  // a video frame's time
  // The input's label: name, else the source's file name.
  std::string Label() const { return name.empty() ? source.filename().string() : name; }
};

struct TrackedPhoto {
  std::filesystem::path source;  // the photo (or the video of a frame)
  std::string name;              // TrackInput::Label()
  std::optional<double> time_s;  // a video frame's time
  double sharpness = 0;          // FaceSharpness of the photo
  Image photo;              // as read, turned upright by its EXIF orientation, alpha composited over white
  FaceDetection detection;  // in the photo's coordinates
  Intrinsics photo_intrinsics;
  FocalSource focal_source = FocalSource::kDefault;
  CropBox crop;
  Image image;  // the dataset image: RGBA crop, alpha = mask
  bool test = false;
  int frame_index = 0;  // within its split
};

struct TrackResult {
  Dataset dataset;                   // root unset; frames in photo order within each split
  std::vector<TrackedPhoto> photos;  // the photos kept, in input order
  std::vector<std::string> skipped;  // "FILE: why" for photos skipped by skip_bad
  TrackFit fit;                      // frames in the order of `photos`
};

// Errors name the file: unreadable, no face, more than one face (unless skip_bad); and no training
// photo left besides the num_test held out. One photo is enough for a fit (the shape prior holds
// the identity), though a dataset of one view trains a poor avatar.
Result<TrackResult> TrackPhotos(const std::vector<std::filesystem::path>& photos, const TrackOptions& options,
                                const FaceLandmarkDetector& detector, const Executor& executor,
                                const std::function<void(const std::string&)>& log = nullptr);
// The same for any inputs (photos and decoded video frames), in input (time) order.
Result<TrackResult> TrackInputs(std::vector<TrackInput> inputs, const TrackOptions& options,
                                const FaceLandmarkDetector& detector, const Executor& executor,
                                const std::function<void(const std::string&)>& log = nullptr);

// The face's 68 landmarks in a photo as the tracker reads them: off MediaPipe's face mesh when `mesh`
// is given (DetectFaceWithMesh), else dlib's shape predictor averaged over shifted boxes.
Result<FaceDetection> DetectTrackLandmarks(const FaceLandmarkDetector& detector, const FaceMesh* mesh,
                                           const Image& photo);

// Fine detail of the face in a photo: the variance of the Laplacian of the grey face (the box of
// its landmarks, resampled to 96 x 96 pixels). Only ratios between frames of one source mean
// anything; 0 without landmarks.
double FaceSharpness(const Image& photo, std::span<const Vec2f> landmarks);

// The per-photo report (track/report.json): source, split, landmark residual, pose, expression.
Json TrackReportJson(const TrackResult& result);

// Writes the dataset into out_dir (which must not exist or be empty): images/, the transforms
// files, track/report.json. Built in a sibling temporary directory and renamed into place, so an
// interrupted run leaves nothing half-written. `extra` files (relative path -> PNG image) go
// along (the overlays).
Status WriteTrackedDataset(const TrackResult& result, const std::filesystem::path& out_dir,
                           const std::vector<std::pair<std::string, Image>>& extra = {});

// The photo files of the arguments: files as given, directories expanded to their .png/.jpg/.jpeg
// files (sorted by name). Errors name a path that does not exist.
Result<std::vector<std::filesystem::path>> ExpandPhotoArguments(
    const std::vector<std::filesystem::path>& args);

}  // namespace icef::track
