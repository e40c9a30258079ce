#include "icef/data/dataset.h"

#include <sstream>

#include "icef/core/enum_table.h"

namespace icef {

namespace {

constexpr std::array<EnumEntry<Tier>, 4> kTierNames = {{{Tier::kObserved, "observed"},
                                                        {Tier::kNear, "near"},
                                                        {Tier::kModerate, "moderate"},
                                                        {Tier::kFar, "far"}}};

}  // namespace

const char* TierName(Tier tier) { return EnumName(kTierNames, tier); }

std::optional<Tier> ParseTier(const std::string& name) { return ParseEnum(kTierNames, name); }

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
     << ", val=" << val.size() << ", expression_dim=" << expression_dim << ", aabb=" << aabb.ToString()
     << ")";
  return os.str();
}

Result<Image> LoadFrameImage(const Dataset& dataset, const Frame& frame) {
  return ReadImage(dataset.ImagePath(frame));
}

}  // namespace icef
