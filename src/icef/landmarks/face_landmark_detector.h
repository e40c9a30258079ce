// dlib's HOG frontal-face detector + 68-point iBUG shape predictor (Debian libdlib-data:
// /usr/share/dlib/shape_predictor_68_face_landmarks.dat). Used by `icef landmarks` to fill in a
// dataset's landmarks and by eval/ to align face chips.
//
// Landmark convention (as in data/dataset.h): pixels, image coordinates with pixel centres at
// +0.5 (dlib puts centres at integers; the conversion is done here).
#pragma once

#include <array>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "icef/core/status.h"
#include "icef/io/image.h"
#include "icef/math/types.h"

namespace icef {

constexpr const char* kDefaultShapePredictorPath = "/usr/share/dlib/shape_predictor_68_face_landmarks.dat";

// One detected face.
struct FaceDetection {
  std::vector<Vec2f> landmarks;   // [68] iBUG-68, image coordinates (+0.5 centres)
  Vec2f box_min = Vec2f::Zero();  // the detector's face box, image coordinates
  Vec2f box_max = Vec2f::Zero();
  int num_faces = 0;       // faces the detector found (the largest is kept)
  bool upsampled = false;  // found only after upsampling the image 2x
  std::string ToString() const;
};

class FaceLandmarkDetector {
 public:
  // Reads the shape predictor (~100 MB). `predictor_path` empty: kDefaultShapePredictorPath.
  static Result<FaceLandmarkDetector> Load(const std::filesystem::path& predictor_path = "");

  // A detector for another thread: its own copy of the face detector's scratch state, sharing the
  // (read-only, thread-safe) shape predictor. Cheap.
  FaceLandmarkDetector Clone() const;

  // The largest face (by detector box area); the image is upsampled 2x once when no face is
  // found at its own size. Error "no face found" when there is none. RGBA images are used as
  // RGB (composite them over their background first). Not thread-safe: one instance (Clone())
  // per thread.
  // averaged: the landmarks are the mean of the shape predictor's, run from a 3 x 3 grid of boxes
  // (the detector's, shifted by 0 or +-kAveragedShift of its width in x and y) on the image and on
  // its mirror image (landmarks mapped back and relabelled): 18 runs instead of one (still
  // milliseconds). The predictor's answer depends on where its box starts it and comes in whole
  // pixels; the mean scatters less and is sub-pixel.
  Result<FaceDetection> DetectFace(const Image& image, bool averaged = false) const;
  static constexpr double kAveragedShift = 0.04;

  // DetectFace(image)->landmarks.
  Result<std::vector<Vec2f>> Detect(const Image& image) const;

  // The iBUG-68 index of each landmark's mirror image (left and right swapped): 0 <-> 16, 36 <-> 45, ...
  static const std::array<int, 68>& MirrorIndex();

 private:
  struct Impl;
  std::shared_ptr<Impl> impl_;
};

}  // namespace icef
