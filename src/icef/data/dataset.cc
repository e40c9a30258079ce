#include "icef/data/dataset.h"

namespace icef {

const char* TierName(Tier tier) {
  switch (tier) {
    case Tier::kObserved: return "observed";
    case Tier::kNear: return "near";
    case Tier::kModerate: return "moderate";
    case Tier::kFar: return "far";
  }
  return "?";
}

std::optional<Tier> ParseTier(const std::string& name) {
  for (Tier t : {Tier::kObserved, Tier::kNear, Tier::kModerate, Tier::kFar})
    if (name == TierName(t)) return t;
  return std::nullopt;
}

std::string Frame::ToString() const { return "Frame(" + file_path + ")"; }
std::string Dataset::ToString() const { return "Dataset(" + root.string() + ")"; }

Result<Dataset> LoadDataset(const std::filesystem::path& dir) {
  return Status::Error(dir.string() + ": dataset loading is not implemented yet");
}
Status SaveDataset(const Dataset& dataset) {
  return Status::Error(dataset.root.string() + ": dataset saving is not implemented yet");
}
Result<Image> LoadFrameImage(const Dataset& dataset, const Frame& frame) { return ReadImage(dataset.ImagePath(frame)); }

}  // namespace icef
