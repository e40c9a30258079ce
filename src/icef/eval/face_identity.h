// Face identity in one call: image (+ optional 68 landmarks) -> aligned chip -> 128-D descriptor.
// Uses the dataset's landmarks when given, otherwise dlib's detector + shape predictor (loaded on
// first use, since it is ~100 MB).
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "icef/core/status.h"
#include "icef/eval/face_chip.h"
#include "icef/eval/face_descriptor.h"

namespace icef::eval {

struct FaceIdentityOptions {
  // Directory holding the face-api model files; empty: $ICEF_FACEID_MODEL or the installed default.
  std::string model_dir;
  // dlib 68-point shape predictor; empty: kDefaultShapePredictorPath.
  std::string predictor_path;
  Status Validate() const { return Status::Ok(); }
  std::string ToString() const;
};

struct FaceIdentityResult {
  FaceDescriptor descriptor{};
  std::vector<Vec2f> landmarks;  // [68] as used for the chip (image coordinates, +0.5 centres)
  bool detected = false;         // true when the landmarks came from the detector
  Image chip;                    // 150x150 aligned chip
};

class FaceIdentity {
 public:
  static Result<FaceIdentity> Load(const FaceIdentityOptions& options);

  // `landmarks`: [68] when known (e.g. from the dataset); otherwise the detector finds them.
  // Not thread-safe (the detector keeps scratch state).
  Result<FaceIdentityResult> Describe(const Image& image, const std::optional<std::vector<Vec2f>>& landmarks);

  const FaceDescriptorNet& net() const { return *net_; }

 private:
  FaceIdentityOptions options_;
  std::shared_ptr<const FaceDescriptorNet> net_;
  std::shared_ptr<FaceLandmarkDetector> detector_;  // loaded on first use
};

}  // namespace icef::eval
