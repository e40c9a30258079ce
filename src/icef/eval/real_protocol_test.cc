#include "icef/eval/real_protocol.h"

#include <gtest/gtest.h>

namespace icef::eval {
namespace {

Image Filled(int w, int h, float r, float g, float b) {
  Image im(w, h, 3);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      im.At(x, y, 0) = r + 0.01f * x;
      im.At(x, y, 1) = g;
      im.At(x, y, 2) = b + 0.01f * y;
    }
  return im;
}

Image Region(int w, int h, int x0, int x1) {
  Image m(w, h, 1);
  for (int y = 0; y < h; ++y)
    for (int x = x0; x < x1; ++x) m.At(x, y, 0) = 1;
  return m;
}

TEST(RealProtocolTest, ExpressionGainIsOneForThePhotoAndZeroForTheNearestRender) {
  const Image photo = Filled(16, 12, 0.2f, 0.5f, 0.3f);
  const Image nearest = Filled(16, 12, 0.4f, 0.4f, 0.3f);
  const Image region = Region(16, 12, 4, 12);
  EXPECT_DOUBLE_EQ(*RealExpressionGain(photo, photo, nearest, region), 1.0);
  EXPECT_DOUBLE_EQ(*RealExpressionGain(photo, nearest, nearest, region), 0.0);
  // Halfway between them in colour: a quarter of the squared error remains.
  Image half = photo;
  for (int y = 0; y < 12; ++y)
    for (int x = 0; x < 16; ++x)
      for (int c = 0; c < 3; ++c) half.At(x, y, c) = 0.5f * (photo.At(x, y, c) + nearest.At(x, y, c));
  EXPECT_NEAR(*RealExpressionGain(photo, half, nearest, region), 0.75, 1e-5);
  // Farther from the photo than the nearest render: negative.
  const Image worse = Filled(16, 12, 0.9f, 0.1f, 0.3f);
  EXPECT_LT(*RealExpressionGain(photo, worse, nearest, region), 0.0);
  // Only the region counts.
  Image outside = photo;
  outside.At(0, 0, 0) = 1;
  EXPECT_DOUBLE_EQ(*RealExpressionGain(photo, outside, nearest, region), 1.0);
  // Nothing to measure: an empty region, or a nearest render equal to the photo.
  EXPECT_FALSE(RealExpressionGain(photo, worse, nearest, Image(16, 12, 1)).has_value());
  EXPECT_FALSE(RealExpressionGain(photo, worse, photo, region).has_value());
}

Frame TrackedFrame(float shift_iod) {
  Frame f;
  Intrinsics k;
  k.width = k.height = 128;
  k.fl_x = k.fl_y = 200;
  k.cx = k.cy = 64;
  Mat4d pose = Mat4d::Identity();
  pose(2, 3) = 3;
  f.camera = Camera(k, pose);
  std::vector<Vec3f> lm3(68);
  for (int i = 0; i < 68; ++i)
    lm3[i] = Vec3f(0.01f * (i % 17) - 0.08f, 0.02f * (i / 17) - 0.03f, 0.05f * (i % 3));
  lm3[36] = Vec3f(-0.2f, 0, 0);
  lm3[39] = Vec3f(-0.1f, 0, 0);
  lm3[42] = Vec3f(0.1f, 0, 0);
  lm3[45] = Vec3f(0.2f, 0, 0);
  std::vector<Vec2f> lm2(68);
  for (int i = 0; i < 68; ++i) lm2[i] = f.camera.Project(lm3[i].cast<double>())->uv.cast<float>();
  const float iod = ((lm2[36] + lm2[39]) * 0.5f - (lm2[42] + lm2[45]) * 0.5f).norm();
  for (int i = 0; i < 68; ++i)
    if (i != 36 && i != 39 && i != 42 && i != 45) lm2[i].x() += shift_iod * iod;
  f.landmarks_2d = lm2;
  f.landmarks_3d = lm3;
  return f;
}

TEST(RealProtocolTest, TrackingResidualInInterOcularDistances) {
  EXPECT_NEAR(*TrackingResidualIod(TrackedFrame(0)), 0.0, 1e-5);
  // 47 of the 51 inner landmarks off by 0.1 IOD (the jaw outline, 0-16, does not count).
  EXPECT_NEAR(*TrackingResidualIod(TrackedFrame(0.1f)), 0.1 * std::sqrt(47.0 / 51.0), 1e-4);
  Frame jaw = TrackedFrame(0);
  for (int i = 0; i < 17; ++i) (*jaw.landmarks_2d)[i].y() += 30;
  EXPECT_NEAR(*TrackingResidualIod(jaw), 0.0, 1e-5);
  Frame none = TrackedFrame(0);
  none.landmarks_3d.reset();
  EXPECT_FALSE(TrackingResidualIod(none).has_value());
}

TEST(RealProtocolTest, NearestTrainingExpression) {
  Dataset d;
  d.train.resize(3);
  d.train[0].expression = {0, 0};
  d.train[1].expression = {1, 0};
  d.train[2].expression = {0, 1};
  const auto [index, delta] = NearestTrainingExpression(d, {0.9f, 0.2f});
  EXPECT_EQ(index, 1);
  EXPECT_NEAR(delta, std::sqrt(0.01 + 0.04), 1e-6);
}

TEST(RealProtocolTest, JsonRoundTripAndMeans) {
  RealEvalResult r;
  r.method = "icef-prior";
  RealFrameMetrics a, b;
  a.file_path = "images/test_000.png";
  a.face_psnr = 20;
  a.real_expr_gain = 0.5;
  b.file_path = "images/test_001.png";
  b.face_psnr = 24;
  r.frames = {a, b};
  r.means = RealMeans::Of(r.frames);
  EXPECT_DOUBLE_EQ(*r.means.face_psnr, 22);
  EXPECT_DOUBLE_EQ(*r.means.real_expr_gain, 0.5);  // over the frames that have it
  EXPECT_FALSE(r.means.lpips.has_value());
  const Result<RealEvalResult> back = RealEvalResult::FromJson(r.ToJson(), "metrics.json");
  ASSERT_TRUE(back.ok()) << back.status().message();
  EXPECT_EQ(back->frames.size(), 2u);
  EXPECT_DOUBLE_EQ(*back->frames[1].face_psnr, 24);
  EXPECT_EQ(back->ToJson(), r.ToJson());
  Json bad = r.ToJson();
  bad["frames"][0]["face_psnr"] = "x";
  const Result<RealEvalResult> err = RealEvalResult::FromJson(bad, "metrics.json");
  ASSERT_FALSE(err.ok());
  EXPECT_NE(err.status().message().find("metrics.json.frames[0].face_psnr"), std::string::npos);
}

}  // namespace
}  // namespace icef::eval
