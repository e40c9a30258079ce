#include "icef/eval/expression_fidelity.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "icef/eval/metrics.h"
#include "icef/testing/box_landmarks.h"

namespace icef::eval {
namespace {

using icef::testing::BoxLandmarks;

// A 32x32 RGB image: `base` everywhere, plus `amount` * a pattern inside [8, 24)^2.
Image Pattern(float base, float amount) {
  Image image(32, 32, 3, base);
  for (int y = 8; y < 24; ++y)
    for (int x = 8; x < 24; ++x)
      for (int c = 0; c < 3; ++c) image.At(x, y, c) += amount * (0.1f + 0.02f * ((x * 7 + y * 3 + c) % 5));
  return image;
}

TEST(ExpressionFidelityTest, KnownGains) {
  const Image region = ExpressionRegion(32, 32, BoxLandmarks(8, 8, 24, 24), {}, 0);
  const Image truth_neutral = Pattern(0.3f, 0.f);
  const Image truth = Pattern(0.3f, 1.f);
  const Image render_neutral = Pattern(0.5f, 0.f);  // the model's neutral may differ from the truth's
  for (const double amount : {0.0, 0.5, 1.0}) {
    const Image render = Pattern(0.5f, static_cast<float>(amount));
    const Result<ExpressionFidelity> f =
        MeasureExpression(render, render_neutral, truth, truth_neutral, region, 1.5);
    ASSERT_TRUE(f.ok()) << f.status().message();
    ASSERT_TRUE(f->gain_coarse.has_value());
    EXPECT_NEAR(*f->gain_coarse, amount, 1e-5)
        << amount;  // both changes are the same pattern: any scale agrees
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
  EXPECT_FALSE(
      MeasureExpression(Bar(30, 1.0), Bar(32, 1.0), truth, truth_neutral, region)->gain_coarse.has_value());
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
