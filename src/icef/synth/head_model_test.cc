#include "icef/synth/head_model.h"

#include <gtest/gtest.h>

#include <cmath>

#include "icef/core/rng.h"
#include "icef/synth/ground_truth_renderer.h"
#include "icef/synth/synthesize.h"

namespace icef::synth {
namespace {

std::vector<float> Zeros() { return std::vector<float>(kNumExpressions, 0.f); }
std::vector<float> One(int e, float v = 1.f) {
  auto b = Zeros();
  b[e] = v;
  return b;
}

TEST(HeadModelTest, ZeroExpressionIsTheNeutralSurface) {
  const HeadModel head(IdentityParams::FromSeed(3));
  const ExpressionState s = head.Prepare(Zeros());
  EXPECT_TRUE(s.neutral);
  EXPECT_FALSE(s.cavity);
  Rng rng(1, StreamId("test"));
  for (int i = 0; i < 200; ++i) {
    const Vec3f x(rng.Uniform(-0.4, 0.4), rng.Uniform(-0.5, 0.45), rng.Uniform(-0.4, 0.45));
    EXPECT_EQ(head.Warp(x, s), x);
  }
}

TEST(HeadModelTest, InverseWarpInvertsTheWarp) {
  const HeadModel head(IdentityParams::FromSeed(4));
  Rng rng(2, StreamId("test"));
  for (int trial = 0; trial < 6; ++trial) {
    std::vector<float> beta(kNumExpressions);
    for (float& b : beta) b = static_cast<float>(rng.Uniform(0.0, 1.5));
    const ExpressionState s = head.Prepare(beta);
    for (int i = 0; i < 40; ++i) {
      // Points near the face, where the warps act.
      const Vec3f p(rng.Uniform(-0.2, 0.2), rng.Uniform(-0.35, 0.15), rng.Uniform(0.15, 0.32));
      const Vec3f x = head.InverseWarp(p, s);
      EXPECT_LT((head.Warp(x, s) - p).norm(), 1e-4f) << "trial " << trial;
    }
  }
}

TEST(HeadModelTest, EachWarpTermIsZeroFarFromItsRegion) {
  const HeadModel head(IdentityParams::Average());
  const Vec3f top_of_head(0.f, 0.38f, 0.f), back_of_head(0.f, 0.05f, -0.36f), ear = head.geometry().ear_c[0];
  for (int e = 0; e < kNumExpressions; ++e) {
    const ExpressionState s = head.Prepare(One(e, 1.5f));
    for (const Vec3f& p : {top_of_head, back_of_head, ear}) EXPECT_EQ(head.Warp(p, s), p) << kExpressionNames[e];
  }
}

TEST(HeadModelTest, LandmarksFollowTheExpression) {
  const HeadModel head(IdentityParams::FromSeed(5));
  const auto neutral = head.Landmarks(head.Prepare(Zeros()));
  for (int i = 0; i < 68; ++i) EXPECT_LT((neutral[i] - head.NeutralLandmarks()[i]).norm(), 1e-5f) << i;
  const auto jaw = head.Landmarks(head.Prepare(One(kJawOpen)));
  EXPECT_LT(jaw[8].y(), neutral[8].y() - 0.03f);    // chin down
  EXPECT_LT(jaw[57].y(), neutral[57].y() - 0.04f);  // lower lip down
  EXPECT_NEAR(jaw[51].y(), neutral[51].y(), 0.005f);  // upper lip stays
  EXPECT_NEAR(jaw[30].y(), neutral[30].y(), 1e-6f);   // nose tip untouched
  const auto blink = head.Landmarks(head.Prepare(One(kEyeCloseRight)));
  const float open = neutral[37].y() - neutral[41].y();
  EXPECT_GT(open, 0.01f);
  EXPECT_LT(std::abs(blink[37].y() - blink[41].y()), 0.2f * open);  // right upper lid met the lower lid
  EXPECT_NEAR(blink[43].y(), neutral[43].y(), 1e-6f);                 // left eye unchanged
  const auto brow = head.Landmarks(head.Prepare(One(kBrowRaiseLeft)));
  EXPECT_GT(brow[24].y(), neutral[24].y() + 0.01f);
  EXPECT_NEAR(brow[19].y(), neutral[19].y(), 1e-6f);
  const auto smile = head.Landmarks(head.Prepare(One(kSmileLeft)));
  EXPECT_GT(smile[54].y(), neutral[54].y() + 0.01f);  // left corner (+x) up
  EXPECT_GT(smile[54].x(), neutral[54].x());
  EXPECT_NEAR(smile[48].y(), neutral[48].y(), 2e-3f);
}

TEST(HeadModelTest, IdentitiesHaveDifferentShapesAndLandmarks) {
  const HeadModel a(IdentityParams::FromSeed(1)), b(IdentityParams::FromSeed(2));
  float total = 0.f;
  for (int i = 0; i < 68; ++i) total += (a.NeutralLandmarks()[i] - b.NeutralLandmarks()[i]).norm();
  EXPECT_GT(total / 68.f, 0.005f);
  EXPECT_NE(IdentityParams::FromSeed(1).ToString(), IdentityParams::FromSeed(2).ToString());
}

TEST(HeadModelTest, LandmarksAreInIbugOrder) {
  const HeadModel head(IdentityParams::Average());
  const auto& l = head.NeutralLandmarks();
  EXPECT_LT(l[0].x(), l[16].x());   // jaw from the subject's right (x < 0) to the left
  EXPECT_LT(l[8].y(), l[57].y());   // chin below the lower lip
  EXPECT_LT(l[17].x(), l[21].x());  // right brow outer -> inner
  EXPECT_LT(l[22].x(), l[26].x());  // left brow inner -> outer
  EXPECT_GT(l[27].y(), l[30].y());  // nose ridge top -> tip
  EXPECT_GT(l[30].z(), l[27].z());  // the tip sticks out
  EXPECT_LT(l[36].x(), l[39].x());  // right eye outer corner first
  EXPECT_LT(l[48].x(), l[54].x());
  EXPECT_GT(l[51].y(), l[57].y());
  for (const Vec3f& p : l) EXPECT_TRUE(head.Bounds().Contains(p));
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
    // The face centre is still a surface point, and the Landmarks stay finite and in the box.
    const auto lm = head.Landmarks(head.Prepare(std::vector<float>(kNumExpressions, v)));
    for (const Vec3f& p : lm) EXPECT_TRUE(p.allFinite() && head.Bounds().Contains(p));
  }
}

}  // namespace
}  // namespace icef::synth
