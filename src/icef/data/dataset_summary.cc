#include "icef/data/dataset_summary.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "icef/core/status.h"

namespace icef {

namespace {

void Extend(std::optional<Range>& range, double v) {
  if (!range) {
    range = Range{v, v};
  } else {
    range->min = std::min(range->min, v);
    range->max = std::max(range->max, v);
  }
}

SplitSummary SummarizeSplit(const std::string& name, const std::vector<Frame>& frames) {
  SplitSummary s;
  s.name = name;
  s.num_frames = static_cast<int>(frames.size());
  for (const Frame& f : frames) {
    s.with_landmarks_2d += f.landmarks_2d.has_value();
    s.with_landmarks_3d += f.landmarks_3d.has_value();
    s.with_neutral += f.neutral_file_path.has_value();
    if (f.tier) {
      ++s.tier_counts[static_cast<int>(*f.tier)];
    } else {
      ++s.without_tier;
    }
    if (f.delta) Extend(s.delta, *f.delta);
  }
  return s;
}

std::optional<Range> PairwiseDistances(const std::vector<Frame>& frames, const Executor& executor) {
  const int64_t n = static_cast<int64_t>(frames.size());
  if (n < 2) return std::nullopt;
  std::vector<Range> per_thread(executor.num_threads(), Range{std::numeric_limits<double>::infinity(),
                                                              -std::numeric_limits<double>::infinity()});
  ParallelFor(executor, n, [&](int64_t begin, int64_t end, int thread) {
    Range& r = per_thread[thread];
    for (int64_t i = begin; i < end; ++i)
      for (int64_t j = i + 1; j < n; ++j) {
        const std::vector<float>& a = frames[i].expression;
        const std::vector<float>& b = frames[j].expression;
        double sum = 0;
        for (size_t k = 0; k < a.size(); ++k) sum += double(a[k] - b[k]) * double(a[k] - b[k]);
        const double d = std::sqrt(sum);
        r.min = std::min(r.min, d);
        r.max = std::max(r.max, d);
      }
  });
  Range total = per_thread[0];
  for (const Range& r : per_thread) {
    total.min = std::min(total.min, r.min);
    total.max = std::max(total.max, r.max);
  }
  return total;
}

std::string Num(double v) {
  std::ostringstream os;
  os.precision(6);
  os << v;
  return os.str();
}

std::string RangeText(const std::optional<Range>& r) {
  if (!r) return "-";
  return r->min == r->max ? Num(r->min) : Num(r->min) + " .. " + Num(r->max);
}

std::string Vec3Text(const Vec3f& v) {
  std::ostringstream os;
  os.precision(6);
  os << "[" << v.x() << ", " << v.y() << ", " << v.z() << "]";
  return os.str();
}

Json RangeJson(const std::optional<Range>& r) {
  if (!r) return nullptr;
  return Json{{"min", r->min}, {"max", r->max}};
}

}  // namespace

const SplitSummary& DatasetSummary::Split(const std::string& name) const {
  for (const SplitSummary& s : splits)
    if (s.name == name) return s;
  ICEF_CHECK(false, "no split named " + name);
  return splits.front();
}

DatasetSummary SummarizeDataset(const Dataset& d, const Executor& executor) {
  DatasetSummary s;
  s.root = d.root.string();
  s.splits = {SummarizeSplit("train", d.train), SummarizeSplit("test", d.test), SummarizeSplit("val", d.val)};
  for (const auto* frames : {&d.train, &d.test, &d.val})
    for (const Frame& f : *frames) {
      const Intrinsics& k = f.camera.intrinsics();
      const std::string res = std::to_string(k.width) + "x" + std::to_string(k.height);
      if (std::find(s.resolutions.begin(), s.resolutions.end(), res) == s.resolutions.end())
        s.resolutions.push_back(res);
      Extend(s.fl_x, k.fl_x);
      Extend(s.fl_y, k.fl_y);
      Extend(s.cx, k.cx);
      Extend(s.cy, k.cy);
    }
  s.aabb = d.aabb;
  s.expression_dim = d.expression_dim;
  s.expression_names = d.expression_names;
  s.background = d.background;
  s.background_file_path = d.background_file_path;
  s.tier_thresholds = d.tier_thresholds;
  s.train_expression_distance = PairwiseDistances(d.train, executor);
  return s;
}

std::string DatasetSummary::ToString() const {
  std::ostringstream os;
  const SplitSummary &train = Split("train"), &test = Split("test"), &val = Split("val");
  os << "dataset " << root << "\n";
  os << "  frames:        train " << train.num_frames << ", test " << test.num_frames << ", val "
     << val.num_frames << "\n";
  std::string res;
  for (const std::string& r : resolutions) res += (res.empty() ? "" : ", ") + r;
  os << "  resolution:    " << (res.empty() ? "-" : res) << "\n";
  os << "  intrinsics:    fl_x " << RangeText(fl_x) << ", fl_y " << RangeText(fl_y) << ", cx "
     << RangeText(cx) << ", cy " << RangeText(cy) << " (pixels)\n";
  os << "  aabb:          " << Vec3Text(aabb.min) << " .. " << Vec3Text(aabb.max) << "\n";
  os << "  expression:    dim " << expression_dim;
  if (!expression_names.empty()) {
    os << ": ";
    constexpr size_t kShown = 16;
    for (size_t i = 0; i < expression_names.size() && i < kShown; ++i)
      os << (i ? ", " : "") << expression_names[i];
    if (expression_names.size() > kShown) os << ", ... (" << expression_names.size() - kShown << " more)";
  } else if (expression_dim > 0) {
    os << " (unnamed)";
  }
  os << "\n";
  os << "  background:    " << Vec3Text(background);
  if (background_file_path) os << " (image " << *background_file_path << ")";
  os << "\n";
  os << "  landmarks:     ";
  std::string separator;
  for (const SplitSummary& s : splits) {
    if (s.num_frames == 0) continue;
    os << separator << s.name << " 2D " << s.with_landmarks_2d << "/" << s.num_frames << ", 3D "
       << s.with_landmarks_3d << "/" << s.num_frames;
    separator = "; ";
  }
  os << "\n";
  os << "  tiers:         ";
  separator.clear();
  for (const SplitSummary& s : splits) {
    if (s.num_frames == s.without_tier) continue;
    os << separator << s.name << ":";
    for (Tier t : {Tier::kObserved, Tier::kNear, Tier::kModerate, Tier::kFar})
      os << " " << TierName(t) << " " << s.tier_counts[static_cast<int>(t)];
    if (s.without_tier) os << ", untiered " << s.without_tier;
    separator = "; ";
  }
  if (separator.empty()) os << "none";
  if (tier_thresholds)
    os << " (thresholds " << Num((*tier_thresholds)[0]) << ", " << Num((*tier_thresholds)[1]) << ")";
  os << "\n";
  os << "  train expression distance (pairwise): ";
  if (train_expression_distance) {
    os << "min " << Num(train_expression_distance->min) << ", max " << Num(train_expression_distance->max)
       << "\n";
  } else {
    os << "- (needs 2+ training frames)\n";
  }
  os << "  test delta:    ";
  if (test.delta) {
    os << "min " << Num(test.delta->min) << ", max " << Num(test.delta->max) << "\n";
  } else {
    os << "-\n";
  }
  if (test.num_frames == 0) os << "  note: no test frames (transforms_test.json missing or empty)\n";
  return os.str();
}

Json DatasetSummary::ToJson() const {
  Json j = Json::object();
  j["root"] = root;
  Json splits_json = Json::object();
  for (const SplitSummary& s : splits) {
    Json tiers = Json::object();
    for (Tier t : {Tier::kObserved, Tier::kNear, Tier::kModerate, Tier::kFar})
      tiers[TierName(t)] = s.tier_counts[static_cast<int>(t)];
    splits_json[s.name] = Json{{"frames", s.num_frames},
                               {"landmarks_2d", s.with_landmarks_2d},
                               {"landmarks_3d", s.with_landmarks_3d},
                               {"neutral_images", s.with_neutral},
                               {"tiers", tiers},
                               {"without_tier", s.without_tier},
                               {"delta", RangeJson(s.delta)}};
  }
  j["splits"] = splits_json;
  j["resolutions"] = resolutions;
  j["intrinsics"] = Json{
      {"fl_x", RangeJson(fl_x)}, {"fl_y", RangeJson(fl_y)}, {"cx", RangeJson(cx)}, {"cy", RangeJson(cy)}};
  j["aabb"] =
      Json::array({Json::array({JsonFloat(aabb.min.x()), JsonFloat(aabb.min.y()), JsonFloat(aabb.min.z())}),
                   Json::array({JsonFloat(aabb.max.x()), JsonFloat(aabb.max.y()), JsonFloat(aabb.max.z())})});
  j["expression_dim"] = expression_dim;
  j["expression_names"] = expression_names;
  j["background"] =
      Json::array({JsonFloat(background.x()), JsonFloat(background.y()), JsonFloat(background.z())});
  j["background_file_path"] = background_file_path ? Json(*background_file_path) : Json(nullptr);
  j["tier_thresholds"] =
      tier_thresholds ? Json::array({(*tier_thresholds)[0], (*tier_thresholds)[1]}) : Json(nullptr);
  j["train_expression_distance"] = RangeJson(train_expression_distance);
  j["test_missing"] = Split("test").num_frames == 0;
  return j;
}

}  // namespace icef
