// Face alignment the way dlib's face descriptor was trained: 68 landmarks ->
// dlib::get_face_chip_details(shape, 150, 0.25) -> dlib::extract_image_chip. Landmarks come from
// the dataset when present, otherwise from dlib's HOG frontal-face detector + 68-point shape
// predictor (Debian libdlib-data: /usr/share/dlib/shape_predictor_68_face_landmarks.dat).
//
// Landmark convention (as in data/dataset.h): pixels, image coordinates with pixel centres at
// +0.5 (dlib puts centres at integers; the conversion is done here).
#pragma once

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "icef/core/status.h"
#include "icef/io/image.h"
#include "icef/math/types.h"

namespace icef::eval {

constexpr const char* kDefaultShapePredictorPath = "/usr/share/dlib/shape_predictor_68_face_landmarks.dat";

// The 150x150 RGB chip (values in [0, 1], quantised to 8 bits as dlib's chips are) of the face
// with these 68 iBUG landmarks. Errors when the landmark count is not 68 or a value is not finite.
Result<Image> ExtractFaceChip(const Image& image, const std::vector<Vec2f>& landmarks);

// dlib's HOG face detector + 68-point shape predictor. Loading reads ~100 MB; Detect is not
// thread-safe (dlib's detector keeps scratch state): use one instance per thread.
class FaceLandmarkDetector {
 public:
  // `predictor_path` empty: kDefaultShapePredictorPath.
  static Result<FaceLandmarkDetector> Load(const std::filesystem::path& predictor_path = "");

  // The 68 landmarks of the largest face found (the image is upsampled 2x once when no face is
  // found at its own size). Error "no face found" when there is none.
  Result<std::vector<Vec2f>> Detect(const Image& image) const;

 private:
  struct Impl;
  std::shared_ptr<Impl> impl_;
};

}  // namespace icef::eval
