#include "icef/eval/face_identity.h"

namespace icef::eval {

std::string FaceIdentityOptions::ToString() const {
  return "FaceIdentityOptions(model_dir=" + ResolveFaceIdModelDir(model_dir).string() + ", predictor=" +
         (predictor_path.empty() ? std::string(kDefaultShapePredictorPath) : predictor_path) + ")";
}

Result<FaceIdentity> FaceIdentity::Load(const FaceIdentityOptions& options) {
  ICEF_RETURN_IF_ERROR(options.Validate());
  FaceIdentity out;
  out.options_ = options;
  ICEF_ASSIGN_OR_RETURN(FaceDescriptorNet net,
                        FaceDescriptorNet::Load(ResolveFaceIdModelDir(options.model_dir)));
  out.net_ = std::make_shared<const FaceDescriptorNet>(std::move(net));
  return out;
}

Result<FaceIdentityResult> FaceIdentity::Describe(const Image& image,
                                                  const std::optional<std::vector<Vec2f>>& landmarks) {
  FaceIdentityResult result;
  if (landmarks.has_value()) {
    result.landmarks = *landmarks;
  } else {
    if (!detector_) {
      ICEF_ASSIGN_OR_RETURN(FaceLandmarkDetector detector,
                            FaceLandmarkDetector::Load(options_.predictor_path));
      detector_ = std::make_shared<FaceLandmarkDetector>(std::move(detector));
    }
    ICEF_ASSIGN_OR_RETURN(result.landmarks, detector_->Detect(image));
    result.detected = true;
  }
  ICEF_ASSIGN_OR_RETURN(result.chip, ExtractFaceChip(image, result.landmarks));
  result.descriptor = net_->Compute(result.chip);
  return result;
}

}  // namespace icef::eval
