#include "icef/model/face_prior.h"

namespace icef {

Result<std::unique_ptr<DeformationPrior>> MakeFacePrior(const ModelSetup&) {
  return Status::Error("face prior: not available yet");
}

}  // namespace icef
