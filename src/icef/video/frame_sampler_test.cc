#include "icef/video/frame_sampler.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <set>

namespace icef {
namespace {

TEST(EvenlySpreadIndicesTest, EndsIncludedAndDistinct) {
  EXPECT_EQ(EvenlySpreadIndices(5, 40), (std::vector<int64_t>{0, 10, 20, 29, 39}));
  EXPECT_EQ(EvenlySpreadIndices(1, 9), (std::vector<int64_t>{4}));
  EXPECT_EQ(EvenlySpreadIndices(4, 3), (std::vector<int64_t>{0, 1, 2}));
  EXPECT_TRUE(EvenlySpreadIndices(4, 0).empty());
  const std::vector<int64_t> tight = EvenlySpreadIndices(99, 100);
  EXPECT_EQ(std::set<int64_t>(tight.begin(), tight.end()).size(), 99u);
}

// Runs the sampler over `decoded` frames, tracking what it holds; returns its choice.
std::vector<int64_t> Sample(int count, int64_t estimate, int64_t decoded, size_t* max_held) {
  EvenFrameSampler sampler(count, estimate);
  std::set<int64_t> held;
  *max_held = 0;
  for (int64_t i = 0; i < decoded; ++i) {
    if (sampler.Offer(i)) held.insert(i);
    for (int64_t r : sampler.TakeReleased()) EXPECT_EQ(held.erase(r), 1u) << r;
    *max_held = std::max(*max_held, held.size());
  }
  const std::vector<int64_t> chosen = sampler.Choose(decoded);
  for (int64_t i : chosen) EXPECT_TRUE(held.count(i)) << i << " was chosen but not held";
  return chosen;
}

TEST(EvenFrameSamplerTest, ExactEstimateGivesTheEvenSpread) {
  size_t max_held = 0;
  EXPECT_EQ(Sample(5, 40, 40, &max_held), EvenlySpreadIndices(5, 40));
  EXPECT_EQ(Sample(7, 1000, 1000, &max_held), EvenlySpreadIndices(7, 1000));
  EXPECT_LE(max_held, 3u * 7 + 1);
}

TEST(EvenFrameSamplerTest, WrongOrMissingEstimateStillCoversTheVideo) {
  for (int64_t estimate : {int64_t(0), int64_t(100), int64_t(3000), int64_t(250)}) {
    for (int64_t decoded : {int64_t(3), int64_t(37), int64_t(1000)}) {
      const int count = 10;
      size_t max_held = 0;
      const std::vector<int64_t> chosen = Sample(count, estimate, decoded, &max_held);
      SCOPED_TRACE("estimate " + std::to_string(estimate) + ", decoded " + std::to_string(decoded));
      ASSERT_EQ(chosen.size(), size_t(std::min<int64_t>(count, decoded)));
      EXPECT_TRUE(std::is_sorted(chosen.begin(), chosen.end()));
      EXPECT_EQ(std::set<int64_t>(chosen.begin(), chosen.end()).size(), chosen.size());
      EXPECT_EQ(chosen.front(), 0);
      const int64_t gap = decoded / count + 1;  // the reserve's spacing bound
      EXPECT_GE(chosen.back(), decoded - gap);
      const std::vector<int64_t> ideal = EvenlySpreadIndices(count, decoded);
      for (size_t k = 0; k < chosen.size(); ++k) EXPECT_LE(std::abs(chosen[k] - ideal[k]), gap) << k;
      EXPECT_LE(max_held, size_t(3 * count + 1));
    }
  }
}

}  // namespace
}  // namespace icef
