// `icef track PHOTOS... --out DATASET`: track/photo_track.h's pipeline with what a user sees: the
// log, an overlay per photo (track/overlay_NNN.png: the photo with the detected landmarks as green
// dots and the fitted face model's landmarks, where the fit put dlib's, as a red outline; beside
// it the dataset image over a checkerboard, which shows the mask), and the summary. With --keep-cameras, an
// existing dataset re-expressed in the face model's expression space instead.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <ostream>
#include <span>
#include <string>
#include <vector>

#include "icef/core/status.h"
#include "icef/track/dataset_retrack.h"
#include "icef/track/photo_track.h"

namespace icef {

struct TrackAppOptions {
  std::vector<std::filesystem::path> photos;  // files or directories
  std::filesystem::path out;
  track::TrackOptions track;
  std::filesystem::path predictor;  // dlib's 68-point shape predictor; empty: the Debian default
  int threads = 0;
  // photos is one dataset directory, re-expressed with its cameras kept (track/dataset_retrack.h).
  bool keep_cameras = false;
  track::RetrackLandmarks landmarks = track::RetrackLandmarks::kDetect;  // with keep_cameras
  bool fit_style = true;  // with keep_cameras and landmarks kDatasetModel (RetrackOptions::fit_style)
  // A video (photos is one video file): which decoded frames are tracked (video/video_reader.h);
  // without either, kDefaultVideoFrames spread over the whole video.
  int every = 0;
  int max_frames = 0;
  bool interactive = false;  // redraw the decoding progress bar in place
};

// Frames tracked from a video when neither --every nor --max-frames is given.
inline constexpr int kDefaultVideoFrames = 24;

// The inputs of `icef track`: photo files (directories expanded), or the sampled frames of one video.
Result<std::vector<track::TrackInput>> LoadTrackInputs(const TrackAppOptions& options, std::ostream& out);

// The overlay of one tracked photo (see above), 384 pixels high.
Image TrackOverlay(const track::TrackResult& result, int photo_index);

// With --keep-cameras, the overlay of one dataset frame (track/overlay_<split>_NNN.png): the frame
// (RGB, or RGBA over `background`) scaled to 384 pixels high, the landmarks the fit used as green
// dots, the fitted face model's landmarks (where the fit put them, in the same convention) as a
// red outline and the mask-edge points the fit used as cyan dots. Points in the frame's pixels.
Image RetrackOverlay(const Image& frame, const Vec3f& background, std::span<const Vec2f> landmarks,
                     std::span<const Vec2f> fitted, std::span<const Vec2f> silhouette = {});

// Which of n frames get a --keep-cameras overlay: all of them up to kMaxRetrackOverlays, else that
// many spread evenly from the first to the last (a NerFace sequence has thousands).
inline constexpr int kMaxRetrackOverlays = 100;
std::vector<int> RetrackOverlayFrames(int n);

// Photos -> dataset (or, with keep_cameras, dataset -> re-expressed dataset).
Status RunTrack(const TrackAppOptions& options, std::ostream& out);

// `icef track` as given on the command line: TrackAppOptions, plus the choices named as there and
// those whose default depends on the mode (photos, or a dataset with app.keep_cameras), which
// ResolveTrackOptions turns into TrackAppOptions.
struct TrackCommandOptions {
  TrackAppOptions app;                       // photos, out, resolution, frames, ...: taken as they are
  std::optional<double> focal;               // photos' focal length, pixels (nullopt: EXIF, else 35 mm)
  std::string face_model = "procedural";     // the model fitted: procedural or ict (track::TrackFaceModel)
  std::string segmentation = "selfie";       // the dataset's alpha mask: selfie, none or selfie-only
  std::string landmarks = "detect";          // with keep_cameras: detect, dlib or model (RetrackLandmarks)
  bool generic_style = false;                // with keep_cameras and landmarks model: no subject style
  std::string detector = "mesh";             // whose 68 landmarks the fit reads: mesh or dlib
  std::string silhouette_region = "face";    // the part of the mask's edge the refit uses: face or head
  std::optional<int> silhouette_points;      // mask-edge points per photo (nullopt: the mode's default)
  std::optional<double> photometric_weight;  // the photometric refit's weight (nullopt: the mode's default)
  std::optional<double> landmark_sigma;      // landmark noise, inter-ocular distances (nullopt: the mode's)
  bool calibrate_detector = false;           // developer: print the detector's calibration table instead
  std::filesystem::path curves;              // a video's ARKit curves to this CSV instead of a dataset
};

// The validation identities `--calibrate-detector` renders (app/detector_calibration.h).
const std::vector<uint64_t>& DetectorCalibrationSeeds();

// The TrackAppOptions the command line describes: the named choices parsed, and the options not
// given at the mode's defaults (track::TrackOptions' for photos, track::RetrackOptions' with
// keep_cameras). Errors name the option.
Result<TrackAppOptions> ResolveTrackOptions(const TrackCommandOptions& options);

// `icef track`: resolves the options, then prints the detector's calibration table on `out` (its
// log on `log`) with calibrate_detector, writes a video's curves with `curves` (app/curves_app.h),
// else tracks (RunTrack).
Status RunTrackCommand(const TrackCommandOptions& options, std::ostream& out, std::ostream& log);

}  // namespace icef
