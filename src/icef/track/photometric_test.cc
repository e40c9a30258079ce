#include "icef/track/photometric.h"

#include <gtest/gtest.h>

#include <cmath>

#include "icef/face/expression.h"

namespace icef::track {
namespace {

TEST(BlurredImageTest, SamplesBilinearlyBetweenPixelCentres) {
  Image image(3, 2, 4);
  for (int y = 0; y < 2; ++y)
    for (int x = 0; x < 3; ++x) {
      image.At(x, y, 0) = static_cast<float>(x);
      image.At(x, y, 1) = static_cast<float>(y);
      image.At(x, y, 2) = static_cast<float>(x * y);
      image.At(x, y, 3) = 0.f;  // alpha is ignored
    }
  const BlurredImage sharp(image, 0.0);
  Vec3d rgb;
  ASSERT_TRUE(sharp.Sample(2.5, 1.5, &rgb));  // the centre of pixel (2, 1)
  EXPECT_DOUBLE_EQ(rgb[0], 2.0);
  EXPECT_DOUBLE_EQ(rgb[1], 1.0);
  EXPECT_DOUBLE_EQ(rgb[2], 2.0);
  ASSERT_TRUE(sharp.Sample(1.25, 0.75, &rgb));  // a quarter of the way across both ways
  EXPECT_NEAR(rgb[0], 0.75, 1e-6);
  EXPECT_NEAR(rgb[1], 0.25, 1e-6);
  EXPECT_NEAR(rgb[2], 0.75 * 0.25, 1e-6);
  rgb = Vec3d::Constant(-1);
  EXPECT_FALSE(sharp.Sample(0.4, 1.0, &rgb));  // left of the first centre
  EXPECT_FALSE(sharp.Sample(1.0, 1.6, &rgb));  // below the last
  EXPECT_EQ(rgb, Vec3d::Constant(-1));
}

TEST(BlurredImageTest, BlurKeepsAConstantAndSpreadsAnEdge) {
  Image image(40, 10, 3, 0.5f);
  const BlurredImage flat(image, 3.0);
  Vec3d rgb;
  ASSERT_TRUE(flat.Sample(5.5, 5.5, &rgb));
  EXPECT_NEAR(rgb[0], 0.5, 1e-6);
  for (int y = 0; y < 10; ++y)
    for (int x = 20; x < 40; ++x) image.At(x, y, 1) = 1.f;
  const BlurredImage edge(image, 3.0);
  ASSERT_TRUE(edge.Sample(20.0, 5.5, &rgb));  // on the edge: halfway
  EXPECT_NEAR(rgb[1], 0.75, 0.02);
  ASSERT_TRUE(edge.Sample(17.5, 5.5, &rgb));  // 2.5 px (0.83 sigma) inside the dark side
  EXPECT_GT(rgb[1], 0.55);
  EXPECT_LT(rgb[1], 0.7);
}

TEST(CanonicalFaceSamplesTest, SkinOfTheFaceWithoutTheEyes) {
  const face::FaceModel model{face::ShapeParams()};
  const face::ExpressionState neutral = model.Prepare(std::vector<float>(face::kNumExpressions, 0.f));
  const std::vector<Vec3f> points = CanonicalFaceSamples(model, 400);
  EXPECT_GT(points.size(), 300u);
  EXPECT_LT(points.size(), 500u);
  const auto& lm = model.NeutralLandmarks();
  float brow_top = lm[17].y();
  for (int i = 17; i <= 26; ++i) brow_top = std::max(brow_top, lm[i].y());
  Vec2f eye_centre[2] = {Vec2f::Zero(), Vec2f::Zero()};
  for (int i = 0; i < 6; ++i)
    eye_centre[0] += lm[36 + i].head<2>() / 6.f, eye_centre[1] += lm[42 + i].head<2>() / 6.f;
  const float eye_half_width = 0.5f * (lm[39] - lm[36]).norm();
  int mouth = 0;
  for (const Vec3f& p : points) {
    EXPECT_LT(std::abs(model.Distance(p, neutral)), 2e-3f);
    EXPECT_EQ(model.Evaluate(p, neutral).material, face::Material::kSkin);
    EXPECT_GT(p.y(), lm[8].y() - 1e-3f);
    EXPECT_LT(p.y(), brow_top + 1e-3f);
    EXPECT_GT(p.z(), 0.f);  // the front
    for (const Vec2f& c : eye_centre) EXPECT_GT((p.head<2>() - c).norm(), eye_half_width);
    mouth += (p.head<2>() - 0.5f * (lm[48] + lm[54]).head<2>()).norm() < 0.5f * (lm[54] - lm[48]).norm();
  }
  EXPECT_GT(mouth, 10);                                 // the lips and around them: where expressions show
  EXPECT_EQ(CanonicalFaceSamples(model, 400), points);  // deterministic
  EXPECT_LT(CanonicalFaceSamples(model, 100).size(), 150u);
}

}  // namespace
}  // namespace icef::track
