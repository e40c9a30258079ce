#include "icef/synth/head_model.h"

#include <gtest/gtest.h>

#include <cmath>

#include "icef/synth/ground_truth_renderer.h"
#include "icef/synth/synthesize.h"

namespace icef::synth {
namespace {

using face::kNumExpressions;

std::vector<float> Zeros() { return std::vector<float>(kNumExpressions, 0.f); }

TEST(HeadModelTest, IdentitiesHaveDifferentShapesAndLandmarks) {
  const HeadModel a(IdentityParams::FromSeed(1)), b(IdentityParams::FromSeed(2));
  EXPECT_EQ(a.face().shape().ToArray(), IdentityParams::FromSeed(1).shape.ToArray());
  EXPECT_NE(a.face().shape().ToArray(), b.face().shape().ToArray());
  float total = 0.f;
  for (int i = 0; i < 68; ++i)
    total += (a.face().NeutralLandmarks()[i] - b.face().NeutralLandmarks()[i]).norm();
  EXPECT_GT(total / 68.f, 0.005f);
  EXPECT_NE(IdentityParams::FromSeed(1).ToString(), IdentityParams::FromSeed(2).ToString());
}

TEST(HeadModelTest, LargeExpressionValuesStillGiveAValidSurface) {
  const HeadModel head(IdentityParams::FromSeed(6));
  Intrinsics in;
  in.width = in.height = 32;
  in.fl_x = in.fl_y = 3.6 * 32;
  in.cx = in.cy = 16;
  const Camera cam = OrbitCamera(in, 3.5, 10.0, 5.0);
  RenderOptions ro;
  ro.supersample = 1;
  const Image neutral = RenderGroundTruth(head, cam, Zeros(), Executor(2), ro);
  for (float v : {1.5f, 2.0f, 3.0f}) {
    const Image img = RenderGroundTruth(head, cam, std::vector<float>(kNumExpressions, v), Executor(2), ro);
    double coverage = 0.0, neutral_coverage = 0.0;
    for (size_t i = 0; i < img.pixels.size(); ++i) ASSERT_TRUE(std::isfinite(img.pixels[i]));
    for (int y = 0; y < 32; ++y)
      for (int x = 0; x < 32; ++x) coverage += img.At(x, y, 3), neutral_coverage += neutral.At(x, y, 3);
    EXPECT_NEAR(coverage, neutral_coverage, 0.15 * neutral_coverage) << "all weights " << v;
  }
}

}  // namespace
}  // namespace icef::synth
