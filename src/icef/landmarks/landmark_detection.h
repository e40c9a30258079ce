// Fills in a dataset's 2D landmarks with dlib's detector (`icef landmarks DATASET`): each selected
// frame is composited over the dataset's background, the largest face's 68 iBUG landmarks are
// detected, and the results are written back into transforms_<split>.json.
//
// Detection (DetectDatasetLandmarks) and writing (WriteDetectedLandmarks) are separate so a
// caller can inspect the report first. Both are deterministic: frames are detected in parallel,
// one detector per thread, each frame into its own slot.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "icef/core/parallel.h"
#include "icef/core/status.h"
#include "icef/data/dataset.h"
#include "icef/landmarks/face_landmark_detector.h"

namespace icef {

struct LandmarkDetectionOptions {
  // Splits to process, any of "train", "test", "val" (a split the dataset lacks is skipped).
  std::vector<std::string> splits = {"train", "test", "val"};
  // Re-detect frames that already have landmarks_2d (otherwise those frames are left untouched).
  bool overwrite = false;
  // dlib 68-point shape predictor; empty: kDefaultShapePredictorPath.
  std::filesystem::path predictor_path;
  // FaceLandmarkDetector::DetectFace's averaged landmarks (icef track's) instead of one run's.
  bool averaged = false;
  // The 68 landmarks read off MediaPipe's face mesh (DetectFaceWithMesh: placed by dlib's averaged
  // landmarks) instead of dlib's; the model from mesh_dir (empty: FaceMesh::Load's default).
  bool mesh = false;
  std::filesystem::path mesh_dir;
  Status Validate() const;
  std::string ToString() const;
};

enum class LandmarkOutcome {
  kKept,      // the frame already had landmarks_2d and overwrite was off: not processed
  kDetected,  // a face was found; `detection` holds it
  kNoFace,    // no face found: the frame keeps whatever landmarks it had (none, unless overwriting)
};
const char* LandmarkOutcomeName(LandmarkOutcome outcome);

struct FrameLandmarks {
  std::string split;      // "train", "test" or "val"
  int index = 0;          // frame index within the split
  std::string file_path;  // the frame's image, relative to the dataset directory
  LandmarkOutcome outcome = LandmarkOutcome::kKept;
  FaceDetection detection;   // when kDetected
  std::string Name() const;  // "train[2] images/train_002.png"
};

struct LandmarkDetectionReport {
  std::vector<FrameLandmarks> frames;  // every frame of the selected splits, by split then index

  int Count(const std::string& split, LandmarkOutcome outcome) const;
  int CountAll(LandmarkOutcome outcome) const;
  // The frames where no face was found (optionally only those of one split).
  std::vector<const FrameLandmarks*> NoFace(const std::string& split = "") const;
  // One line per processed split ("train: 5 frames, 5 detected, 0 without a face, 0 kept"), then
  // the frames without a face, one per line.
  std::string Summary() const;
  std::string ToString() const { return Summary(); }
};

// Detects the landmarks of the selected frames. Errors (an unreadable image, a missing predictor)
// name the file; a frame without a face is not an error but an outcome in the report.
// `progress(done, total)` is called (serialised, from worker threads) after each detected frame.
Result<LandmarkDetectionReport> DetectDatasetLandmarks(
    const Dataset& dataset, const LandmarkDetectionOptions& options, const Executor& executor,
    const std::function<void(int64_t done, int64_t total)>& progress = nullptr);

// Writes the report's detected landmarks into dataset.root/transforms_<split>.json: those frames
// get "landmarks_2d" ([68] [x, y], pixels) and "landmarks_2d_visible" (68 x true); every other key
// of the files is kept as it was (keys of other tools, NerFace/instant-ngp layouts). Each file is
// replaced atomically and only files with detected frames are rewritten. Errors if a file no
// longer matches the dataset (its frame count changed since LoadDataset).
Status WriteDetectedLandmarks(const Dataset& dataset, const LandmarkDetectionReport& report);

// The image the detector sees: the frame's image composited over the dataset's background (its
// background image when it has one of the same size, else its background colour).
Result<Image> LoadDetectionImage(const Dataset& dataset, const Frame& frame, const Image& background_image);

}  // namespace icef
