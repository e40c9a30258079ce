#include "icef/data/dataset_summary.h"

#include <gtest/gtest.h>

#include <cmath>

#include "icef/testing/tiny_dataset.h"

namespace icef {
namespace {

double Distance(const std::vector<float>& a, const std::vector<float>& b) {
  double s = 0;
  for (size_t i = 0; i < a.size(); ++i) s += double(a[i] - b[i]) * double(a[i] - b[i]);
  return std::sqrt(s);
}

TEST(DatasetSummary, CountsAndRangesMatchABruteForceReference) {
  const auto dir = testing::MakeTempDir("summary_counts");
  testing::TinyDatasetOptions options;
  options.num_train = 5;
  options.num_test = 4;
  options.landmarks_3d = true;
  testing::WriteTinyDataset(dir, options);
  const Dataset d = LoadDataset(dir).value();
  const DatasetSummary s = SummarizeDataset(d, Executor(2));
  EXPECT_EQ(s.Split("train").num_frames, 5);
  EXPECT_EQ(s.Split("test").num_frames, 4);
  EXPECT_EQ(s.Split("val").num_frames, 0);
  EXPECT_EQ(s.Split("train").with_landmarks_2d, 5);
  EXPECT_EQ(s.Split("test").with_landmarks_3d, 4);
  EXPECT_EQ(s.resolutions, std::vector<std::string>{"8x6"});
  EXPECT_EQ(s.fl_x->min, 9.6);
  EXPECT_EQ(s.fl_x->max, 9.6);

  double lo = 1e300, hi = 0;
  for (size_t i = 0; i < d.train.size(); ++i)
    for (size_t j = i + 1; j < d.train.size(); ++j) {
      lo = std::min(lo, Distance(d.train[i].expression, d.train[j].expression));
      hi = std::max(hi, Distance(d.train[i].expression, d.train[j].expression));
    }
  ASSERT_TRUE(s.train_expression_distance.has_value());
  EXPECT_DOUBLE_EQ(s.train_expression_distance->min, lo);
  EXPECT_DOUBLE_EQ(s.train_expression_distance->max, hi);
  EXPECT_LT(lo, hi);

  int tiers = 0;
  double dmin = 1e300, dmax = -1;
  for (const Frame& f : d.test) {
    ++tiers;
    dmin = std::min(dmin, *f.delta);
    dmax = std::max(dmax, *f.delta);
  }
  const auto& counts = s.Split("test").tier_counts;
  EXPECT_EQ(counts[0] + counts[1] + counts[2] + counts[3], tiers);
  EXPECT_GE(counts[static_cast<int>(Tier::kObserved)], 1);
  EXPECT_EQ(s.Split("test").delta->min, dmin);
  EXPECT_EQ(s.Split("test").delta->max, dmax);

  // Thread count does not change anything.
  const DatasetSummary s1 = SummarizeDataset(d, Executor(1));
  EXPECT_EQ(s1.ToJson(), s.ToJson());
  EXPECT_EQ(s1.ToString(), s.ToString());
}

TEST(DatasetSummary, TextAndJsonMentionTheEssentials) {
  const auto dir = testing::MakeTempDir("summary_text");
  testing::TinyDatasetOptions options;
  options.num_test = 0;
  testing::WriteTinyDataset(dir, options);
  const DatasetSummary s = SummarizeDataset(LoadDataset(dir).value(), Executor(1));
  const std::string text = s.ToString();
  for (const char* needle : {"train 3, test 0, val 0", "8x6", "dim 4: e0, e1, e2, e3", "no test frames",
                             "train expression distance (pairwise): min "})
    EXPECT_NE(text.find(needle), std::string::npos) << needle << "\n" << text;
  const Json j = s.ToJson();
  EXPECT_EQ(j["splits"]["train"]["frames"], 3);
  EXPECT_EQ(j["expression_dim"], 4);
  EXPECT_TRUE(j["test_missing"].get<bool>());
  EXPECT_TRUE(j["train_expression_distance"]["min"].is_number());
}

}  // namespace
}  // namespace icef
