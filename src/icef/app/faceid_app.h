// `icef faceid IMAGE... [--landmarks-from DATASET] [--json] [--faceid-model DIR]`: each image's
// 128-D face descriptor (dlib's ResNet, run by eval/face_descriptor) and the pairwise Euclidean
// distances and cosine similarities; pairs under eval::kSamePersonThreshold are flagged as the same
// person. Landmarks come from the dataset when landmarks_from names one holding the image,
// otherwise from dlib's face detector.
#pragma once

#include <filesystem>
#include <ostream>
#include <string>
#include <vector>

#include "icef/core/status.h"

namespace icef {

struct FaceIdAppOptions {
  std::vector<std::string> images;  // photos (PNG / JPEG) with one face each, printed as given
  std::filesystem::path
      landmarks_from;               // dataset whose frames' landmarks serve the images it holds (empty: none)
  std::filesystem::path model_dir;  // face-identity model directory (empty: the default lookup)
  bool json = false;                // print one JSON document instead of the table

  // Errors name the option.
  Status Validate() const;
};

// The face-identity model directory used when none is given and $ICEF_FACEID_MODEL is unset.
std::string DefaultFaceIdModelDir();

// Describes every image and prints the descriptors and pairwise distances on `out`.
Status RunFaceId(const FaceIdAppOptions& options, std::ostream& out);

}  // namespace icef
