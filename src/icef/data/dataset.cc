#include "icef/data/dataset.h"

#include <sstream>

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

std::string Frame::ToString() const {
  std::ostringstream os;
  os << "Frame(" << file_path << ", " << camera.width() << "x" << camera.height() << ", expression["
     << expression.size() << "]";
  if (landmarks_2d) os << ", landmarks_2d";
  if (landmarks_3d) os << ", landmarks_3d";
  if (delta) os << ", delta=" << *delta;
  if (tier) os << ", tier=" << TierName(*tier);
  os << ")";
  return os.str();
}

std::string Dataset::ToString() const {
  std::ostringstream os;
  os << "Dataset(" << root.string() << ", train=" << train.size() << ", test=" << test.size()
     << ", val=" << val.size() << ", expression_dim=" << expression_dim << ", aabb=" << aabb.ToString() << ")";
  return os.str();
}

Result<Image> LoadFrameImage(const Dataset& dataset, const Frame& frame) { return ReadImage(dataset.ImagePath(frame)); }

}  // namespace icef
