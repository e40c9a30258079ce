#include "icef/synth/ground_truth_renderer.h"

#include <gtest/gtest.h>

#include <cmath>

#include "icef/synth/synthesize.h"

namespace icef::synth {
namespace {

using face::ExpressionRegionLandmarks;
using face::kBrowRaiseLeft;
using face::kExpressionNames;
using face::kJawOpen;
using face::kNumExpressions;
using face::kSmileLeft;

constexpr int kRes = 64;

Camera TestCamera(double yaw = 0.0, double pitch = 0.0, int res = kRes) {
  Intrinsics in;
  in.width = in.height = res;
  in.fl_x = in.fl_y = 3.6 * res;
  in.cx = in.cy = 0.5 * res;
  return OrbitCamera(in, 3.5, yaw, pitch);
}

std::vector<float> Zeros() { return std::vector<float>(kNumExpressions, 0.f); }

TEST(GroundTruthRendererTest, DeterministicAndIndependentOfThreads) {
  const HeadModel head(IdentityParams::FromSeed(11));
  std::vector<float> beta = Zeros();
  beta[kJawOpen] = 0.6f, beta[kSmileLeft] = 0.4f;
  const Image a = RenderGroundTruth(head, TestCamera(20, 5, 32), beta, Executor(1));
  const Image b = RenderGroundTruth(head, TestCamera(20, 5, 32), beta, Executor(2));
  const Image c = RenderGroundTruth(head, TestCamera(20, 5, 32), beta, Executor(2));
  EXPECT_EQ(a.pixels, b.pixels);
  EXPECT_EQ(b.pixels, c.pixels);
  EXPECT_EQ(EncodePng(a), EncodePng(c));
}

TEST(GroundTruthRendererTest, CanonicalShadingChangesOnlyTheShadingOfExpressions) {
  const HeadModel head(IdentityParams::FromSeed(12));
  RenderOptions canonical;
  canonical.canonical_shading = true;
  // Neutral: every point is its own canonical point, so the two renders are the same.
  EXPECT_EQ(RenderGroundTruth(head, TestCamera(15, 5), Zeros(), Executor(2)).pixels,
            RenderGroundTruth(head, TestCamera(15, 5), Zeros(), Executor(2), canonical).pixels);
  std::vector<float> beta = Zeros();
  beta[kJawOpen] = 0.9f, beta[face::kCheekPuff] = 1.f;
  const Image observed = RenderGroundTruth(head, TestCamera(15, 5), beta, Executor(2));
  const Image moved = RenderGroundTruth(head, TestCamera(15, 5), beta, Executor(2), canonical);
  double changed = 0, coverage_diff = 0;
  for (int y = 0; y < kRes; ++y)
    for (int x = 0; x < kRes; ++x) {
      coverage_diff += std::abs(observed.At(x, y, 3) - moved.At(x, y, 3));  // same geometry
      // The same albedo under other light: the colour's chromaticity stays, its brightness moves.
      if (observed.At(x, y, 3) == 1.f && std::abs(observed.At(x, y, 1) - moved.At(x, y, 1)) > 0.02f)
        ++changed;
    }
  EXPECT_EQ(coverage_diff, 0.0);
  EXPECT_GT(changed, 20) << "the opened jaw and the puffed cheeks should be shaded as at neutral";
}

TEST(GroundTruthRendererTest, WhiteBackgroundAlphaMaskAndAFaceInTheMiddle) {
  const HeadModel head(IdentityParams::Average());
  const Image img = RenderGroundTruth(head, TestCamera(), Zeros(), Executor(2));
  ASSERT_EQ(img.channels, 4);
  EXPECT_EQ(img.At(0, 0, 3), 0.f);
  EXPECT_EQ(img.At(0, 0, 0), 1.f);  // background RGB where nothing is hit
  EXPECT_EQ(img.At(kRes / 2, kRes / 2, 3), 1.f);
  bool partial = false;
  double coverage = 0.0;
  for (int y = 0; y < kRes; ++y)
    for (int x = 0; x < kRes; ++x) {
      const float a = img.At(x, y, 3);
      partial = partial || (a > 0.f && a < 1.f);  // 2x2 supersampled edges
      coverage += a;
    }
  EXPECT_TRUE(partial);
  EXPECT_GT(coverage / (kRes * kRes), 0.25);  // the face fills a good part of the frame
  EXPECT_LT(coverage / (kRes * kRes), 0.8);
}

TEST(GroundTruthRendererTest, DifferentIdentitiesLookDifferent) {
  const Image a =
      RenderGroundTruth(HeadModel(IdentityParams::FromSeed(1)), TestCamera(), Zeros(), Executor(2));
  const Image b =
      RenderGroundTruth(HeadModel(IdentityParams::FromSeed(2)), TestCamera(), Zeros(), Executor(2));
  double diff = 0.0;
  for (size_t i = 0; i < a.pixels.size(); ++i) diff += std::abs(a.pixels[i] - b.pixels[i]);
  EXPECT_GT(diff / a.pixels.size(), 0.02);
}

// Each expression parameter changes pixels only near its own region's landmarks: outside the
// landmarks' bounding box (neutral and expressed) dilated by a margin, the change is ~0; inside,
// the image does change.
TEST(GroundTruthRendererTest, EachExpressionMovesOnlyItsRegion) {
  const HeadModel head(IdentityParams::FromSeed(12));
  const Camera cam = TestCamera(0.0, 0.0);
  const Image neutral = RenderGroundTruth(head, cam, Zeros(), Executor(2));
  const LandmarkView neutral_lm = ProjectLandmarks(head, cam, Zeros());
  const float px_per_unit = static_cast<float>(cam.intrinsics().fl_x / 3.5);
  for (int e = 0; e < kNumExpressions; ++e) {
    std::vector<float> beta = Zeros();
    beta[e] = 1.f;
    const Image img = RenderGroundTruth(head, cam, beta, Executor(2));
    const LandmarkView lm = ProjectLandmarks(head, cam, beta);
    Vec2f lo = Vec2f::Constant(1e9f), hi = Vec2f::Constant(-1e9f);
    for (int i : ExpressionRegionLandmarks(e)) {
      for (const Vec2f& p : {neutral_lm.landmarks_2d[i], lm.landmarks_2d[i]})
        lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
    }
    // The warp windows reach ~0.1 head units beyond the landmarks; the jaw also stretches the neck.
    const float margin = (e == kJawOpen ? 0.2f : 0.1f) * px_per_unit;
    lo.array() -= margin;
    hi.array() += margin;
    float outside = 0.f, inside = 0.f;
    for (int y = 0; y < kRes; ++y)
      for (int x = 0; x < kRes; ++x) {
        float change = 0.f;
        for (int c = 0; c < 4; ++c)
          change = std::max(change, std::abs(img.At(x, y, c) - neutral.At(x, y, c)));
        const bool in_region = x + 1 >= lo.x() && x <= hi.x() && y + 1 >= lo.y() && y <= hi.y();
        (in_region ? inside : outside) = std::max(in_region ? inside : outside, change);
      }
    EXPECT_LT(outside, 0.02f) << kExpressionNames[e];
    EXPECT_GT(inside, 0.05f) << kExpressionNames[e];
  }
}

TEST(GroundTruthRendererTest, VisibleLandmarksProjectOntoTheFace) {
  const HeadModel head(IdentityParams::FromSeed(13));
  std::vector<float> beta = Zeros();
  beta[kJawOpen] = 0.5f, beta[kBrowRaiseLeft] = 0.7f;
  for (double yaw : {-35.0, 0.0, 20.0, 35.0}) {
    const Camera cam = TestCamera(yaw, yaw == 0.0 ? 0.0 : 10.0);
    const Image img = RenderGroundTruth(head, cam, beta, Executor(2));
    const LandmarkView lm = ProjectLandmarks(head, cam, beta);
    int visible = 0, on_face = 0;
    for (int i = 0; i < 68; ++i) {
      if (!lm.visible[i]) continue;
      ++visible;
      const int x = static_cast<int>(lm.landmarks_2d[i].x()), y = static_cast<int>(lm.landmarks_2d[i].y());
      ASSERT_TRUE(x >= 0 && y >= 0 && x < kRes && y < kRes);
      // Covered at least partly: jaw-contour landmarks lie on the silhouette, so their pixel may
      // straddle the edge (1 of the 2x2 samples hits; the style moves which ones do).
      on_face += img.At(x, y, 3) > 0.f;
    }
    EXPECT_EQ(on_face, visible) << "yaw " << yaw;
    if (yaw == 0.0) {
      EXPECT_GE(visible, 64);
    }
    if (std::abs(yaw) == 35.0) {
      EXPECT_LT(visible, 68) << "the far jaw contour is hidden at yaw " << yaw;
    }
  }
}

}  // namespace
}  // namespace icef::synth
