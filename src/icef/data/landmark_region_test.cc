#include "icef/data/landmark_region.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "icef/testing/box_landmarks.h"

namespace icef {
namespace {

using icef::testing::BoxLandmarks;

TEST(LandmarkRegionTest, IndicesAreBrowsEyesAndMouth) {
  const std::vector<int>& idx = ExpressionLandmarkIndices();
  ASSERT_EQ(idx.size(), 10u + 32u);
  EXPECT_EQ(idx.front(), 17);
  EXPECT_EQ(idx[9], 26);
  EXPECT_EQ(idx[10], 36);
  EXPECT_EQ(idx.back(), 67);
  EXPECT_EQ(DefaultRegionDilation(128), 3);
  EXPECT_EQ(DefaultRegionDilation(256), 6);
  EXPECT_EQ(DefaultRegionDilation(16), 1);
}

TEST(LandmarkRegionTest, ExpressionRegionIsTheDilatedHullOfBothLandmarkSets) {
  const Image region = ExpressionRegion(32, 32, BoxLandmarks(8, 8, 16, 16), BoxLandmarks(20, 20, 24, 24), 1);
  EXPECT_EQ(region.At(12, 12, 0), 1.f);  // inside the frame's hull
  EXPECT_EQ(region.At(21, 21, 0), 1.f);  // inside the neutral's hull
  EXPECT_EQ(region.At(16, 12, 0), 1.f);  // centre 16.5 is 0.5 px outside: within the dilation
  EXPECT_EQ(region.At(18, 12, 0), 0.f);  // 2.5 px outside
  EXPECT_EQ(region.At(18, 18, 0), 0.f);  // between the two hulls
  EXPECT_EQ(region.At(0, 0, 0), 0.f);
  int inside = 0;
  for (float v : region.pixels) inside += v > 0.5f;
  // Two squares (8x8 and 4x4 pixel centres inside) grown by about one pixel on each side.
  EXPECT_GT(inside, 64 + 16);
  EXPECT_LT(inside, 10 * 10 + 6 * 6 + 1);
  // No neutral landmarks: the frame's hull alone.
  const Image alone = ExpressionRegion(32, 32, BoxLandmarks(8, 8, 16, 16), {}, 1);
  EXPECT_EQ(alone.At(21, 21, 0), 0.f);
}

int Count(const Image& mask) {
  int n = 0;
  for (float v : mask.pixels) n += v > 0.5f;
  return n;
}

TEST(LandmarkRegionTest, HullRegionIsTheFilledLandmarkHull) {
  // A square [2, 10]^2 of landmarks (corners, edge midpoints, the centre), plus unusable points.
  const float nan = std::nanf("");
  const std::vector<Vec2f> square = {{2, 2}, {10, 2}, {10, 10}, {2, 10},
                                     {6, 2}, {6, 6},  {nan, 3}, {4, INFINITY}};
  const Image region = LandmarkHullRegion(16, 12, square);
  ASSERT_EQ(region.width, 16);
  ASSERT_EQ(region.height, 12);
  EXPECT_EQ(Count(region), 64);  // pixel centres 2.5 .. 9.5: 8 x 8
  EXPECT_EQ(region.At(2, 2, 0), 1.f);
  EXPECT_EQ(region.At(9, 9, 0), 1.f);
  EXPECT_EQ(region.At(10, 5, 0), 0.f);
  EXPECT_EQ(region.At(1, 5, 0), 0.f);
  // Not a bounding box: a right triangle (0,0), (8,0), (0,8) holds the 36 centres with x + y <= 7.
  EXPECT_EQ(Count(LandmarkHullRegion(16, 12, {{0, 0}, {8, 0}, {0, 8}})), 36);
  // Points outside the image shape the hull; the image clips it.
  EXPECT_EQ(Count(LandmarkHullRegion(16, 12, {{-4, -4}, {4, -4}, {4, 4}, {-4, 4}})), 16);
  EXPECT_EQ(Count(LandmarkHullRegion(16, 12, {{-10, -10}, {30, -10}, {30, 30}, {-10, 30}})), 16 * 12);
  // Fewer than three usable or non-collinear points: nothing.
  EXPECT_EQ(Count(LandmarkHullRegion(16, 12, {})), 0);
  EXPECT_EQ(Count(LandmarkHullRegion(16, 12, {{2, 2}, {10, 10}, {nan, nan}})), 0);
  EXPECT_EQ(Count(LandmarkHullRegion(16, 12, {{2, 2}, {6, 6}, {10, 10}})), 0);
}

}  // namespace
}  // namespace icef
