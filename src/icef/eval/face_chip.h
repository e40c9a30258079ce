// Face alignment the way dlib's face descriptor was trained: 68 landmarks ->
// dlib::get_face_chip_details(shape, 150, 0.25) -> dlib::extract_image_chip. Landmarks come from
// the dataset when present, otherwise from dlib's HOG frontal-face detector + 68-point shape
// predictor (landmarks/face_landmark_detector.h).
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
#include "icef/landmarks/face_landmark_detector.h"
#include "icef/math/types.h"

namespace icef::eval {

// The 150x150 RGB chip (values in [0, 1], quantised to 8 bits as dlib's chips are) of the face
// with these 68 iBUG landmarks. Errors when the landmark count is not 68 or a value is not finite.
Result<Image> ExtractFaceChip(const Image& image, const std::vector<Vec2f>& landmarks);

// The detector moved to landmarks/ (a lower module, also used by `icef landmarks`); these names
// keep eval::FaceLandmarkDetector and eval::kDefaultShapePredictorPath working.
using ::icef::FaceLandmarkDetector;
using ::icef::kDefaultShapePredictorPath;

}  // namespace icef::eval
