#include "icef/eval/expression_fidelity.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "icef/eval/metrics.h"

namespace icef::eval {
namespace {

// 68 landmarks whose brow/eye/mouth points span the box [x0, x1] x [y0, y1]; the others far away.
std::vector<Vec2f> BoxLandmarks(float x0, float y0, float x1, float y1) {
  std::vector<Vec2f> l(68, Vec2f(1000.f, 1000.f));
  const Vec2f corners[4] = {{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}};
  int j = 0;
  for (int i : ExpressionLandmarkIndices()) l[i] = corners[j++ % 4];
  return l;
}

// A 32x32 RGB image: `base` everywhere, plus `amount` * a pattern inside [8, 24)^2.
Image Pattern(float base, float amount) {
  Image image(32, 32, 3, base);
  for (int y = 8; y < 24; ++y)
    for (int x = 8; x < 24; ++x)
      for (int c = 0; c < 3; ++c) image.At(x, y, c) += amount * (0.1f + 0.02f * ((x * 7 + y * 3 + c) % 5));
  return image;
}

TEST(ExpressionFidelityTest, RegionIsTheDilatedHullOfBothLandmarkSets) {
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

TEST(ExpressionFidelityTest, FaceRegionIsTheFilledLandmarkHull) {
  // A square [2, 10]^2 of landmarks (corners, edge midpoints, the centre), plus unusable points.
  const float nan = std::nanf("");
  const std::vector<Vec2f> square = {{2, 2}, {10, 2}, {10, 10}, {2, 10}, {6, 2}, {6, 6}, {nan, 3}, {4, INFINITY}};
  const Image region = FaceRegion(16, 12, square);
  ASSERT_EQ(region.width, 16);
  ASSERT_EQ(region.height, 12);
  EXPECT_EQ(Count(region), 64);  // pixel centres 2.5 .. 9.5: 8 x 8
  EXPECT_EQ(region.At(2, 2, 0), 1.f);
  EXPECT_EQ(region.At(9, 9, 0), 1.f);
  EXPECT_EQ(region.At(10, 5, 0), 0.f);
  EXPECT_EQ(region.At(1, 5, 0), 0.f);
  // Not a bounding box: a right triangle (0,0), (8,0), (0,8) holds the 36 centres with x + y <= 7.
  EXPECT_EQ(Count(FaceRegion(16, 12, {{0, 0}, {8, 0}, {0, 8}})), 36);
  // Points outside the image shape the hull; the image clips it.
  EXPECT_EQ(Count(FaceRegion(16, 12, {{-4, -4}, {4, -4}, {4, 4}, {-4, 4}})), 16);
  EXPECT_EQ(Count(FaceRegion(16, 12, {{-10, -10}, {30, -10}, {30, 30}, {-10, 30}})), 16 * 12);
  // Fewer than three usable or non-collinear points: nothing.
  EXPECT_EQ(Count(FaceRegion(16, 12, {})), 0);
  EXPECT_EQ(Count(FaceRegion(16, 12, {{2, 2}, {10, 10}, {nan, nan}})), 0);
  EXPECT_EQ(Count(FaceRegion(16, 12, {{2, 2}, {6, 6}, {10, 10}})), 0);
}

TEST(ExpressionFidelityTest, KnownGains) {
  const Image region = ExpressionRegion(32, 32, BoxLandmarks(8, 8, 24, 24), {}, 0);
  const Image truth_neutral = Pattern(0.3f, 0.f);
  const Image truth = Pattern(0.3f, 1.f);
  const Image render_neutral = Pattern(0.5f, 0.f);  // the model's neutral may differ from the truth's
  for (const double amount : {0.0, 0.5, 1.0}) {
    const Image render = Pattern(0.5f, static_cast<float>(amount));
    const Result<ExpressionFidelity> f = MeasureExpression(render, render_neutral, truth, truth_neutral, region, 1.5);
    ASSERT_TRUE(f.ok()) << f.status().message();
    ASSERT_TRUE(f->gain_coarse.has_value());
    EXPECT_NEAR(*f->gain_coarse, amount, 1e-5) << amount;  // both changes are the same pattern: any scale agrees
    EXPECT_FALSE(f->negligible);
    EXPECT_EQ(f->pixels, 16 * 16);
    ASSERT_TRUE(f->gain.has_value());
    EXPECT_NEAR(*f->gain, amount, 1e-5) << amount;
    if (amount == 0.0) {
      EXPECT_FALSE(f->corr.has_value());  // no change at all: no direction to compare
    } else {
      EXPECT_NEAR(*f->corr, 1.0, 1e-6);
    }
  }
  // A change in the wrong place (outside the region) counts for nothing; the opposite change is -1.
  Image elsewhere = render_neutral;
  elsewhere.At(2, 2, 0) += 0.9f;
  EXPECT_NEAR(*MeasureExpression(elsewhere, render_neutral, truth, truth_neutral, region)->gain, 0.0, 1e-9);
  const Image opposite = Pattern(0.5f, -1.f);
  const auto f = MeasureExpression(opposite, render_neutral, truth, truth_neutral, region);
  EXPECT_NEAR(*f->gain, -1.0, 1e-5);
  EXPECT_NEAR(*f->corr, -1.0, 1e-6);
}

// A 64x64 grey image with a dark horizontal bar whose top edge lies at row `top`, optionally
// blurred by a Gaussian of `blur` pixels (a render that has the expression but is soft).
Image Bar(double top, double blur) {
  std::vector<double> plane(64 * 64);
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x) plane[size_t(y) * 64 + x] = (y + 0.5 >= top && y < 40) ? 0.1 : 0.7;
  plane = GaussianFilter(plane, 64, 64, blur);
  Image image(64, 64, 3, 0.f);
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x)
      for (int c = 0; c < 3; ++c) image.At(x, y, c) = static_cast<float>(plane[size_t(y) * 64 + x]);
  return image;
}

TEST(ExpressionFidelityTest, CoarseGainForgivesSoftnessNotAbsence) {
  EXPECT_DOUBLE_EQ(DefaultCoarseSigma(128), 2.0);
  EXPECT_DOUBLE_EQ(DefaultCoarseSigma(256), 4.0);
  // The "expression" raises the bar's top edge by two pixels (a brow lifting).
  const Image region = ExpressionRegion(64, 64, BoxLandmarks(8, 20, 56, 44), {}, 0);
  const Image truth_neutral = Bar(32, 0), truth = Bar(30, 0);
  // A render with all of the expression, one pixel softer than the truth.
  const auto soft = MeasureExpression(Bar(30, 1.0), Bar(32, 1.0), truth, truth_neutral, region, 2.0);
  ASSERT_TRUE(soft.ok()) << soft.status().message();
  EXPECT_LT(*soft->gain, 0.8);
  EXPECT_GT(*soft->gain_coarse, 0.9);
  // Half of the expression (the edge raised by one pixel), as soft: about half at the coarse scale.
  const auto half = MeasureExpression(Bar(31, 1.0), Bar(32, 1.0), truth, truth_neutral, region, 2.0);
  EXPECT_NEAR(*half->gain_coarse, 0.5, 0.1);
  // None of it: zero at every scale.
  const auto none = MeasureExpression(Bar(32, 1.0), Bar(32, 1.0), truth, truth_neutral, region, 2.0);
  EXPECT_NEAR(*none->gain_coarse, 0.0, 1e-12);
  // Without a coarse scale there is no coarse gain.
  EXPECT_FALSE(MeasureExpression(Bar(30, 1.0), Bar(32, 1.0), truth, truth_neutral, region)->gain_coarse.has_value());
}

TEST(ExpressionFidelityTest, NegligibleTruthAndErrors) {
  const Image region = ExpressionRegion(32, 32, BoxLandmarks(8, 8, 24, 24), {}, 0);
  const Image neutral = Pattern(0.3f, 0.f);
  const Image tiny = Pattern(0.3f, 0.001f);
  const auto f = MeasureExpression(Pattern(0.3f, 1.f), neutral, tiny, neutral, region);
  ASSERT_TRUE(f.ok());
  EXPECT_TRUE(f->negligible);
  EXPECT_FALSE(f->gain.has_value());
  EXPECT_LT(f->true_rms, kNegligibleExpressionRms);
  const Image small(16, 16, 3, 0.f);
  const auto bad = MeasureExpression(small, neutral, neutral, neutral, region);
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.status().message().find("region's size 32x32"), std::string::npos) << bad.status().message();
  EXPECT_EQ(DefaultRegionDilation(128), 3);
  EXPECT_EQ(DefaultRegionDilation(32), 1);
  EXPECT_EQ(DefaultRegionDilation(512), 12);
}

}  // namespace
}  // namespace icef::eval
