// icef track --keep-cameras overlays: the frame over its background, scaled to 384 pixels high,
// the landmarks as green dots where they are and the fitted model as a red outline; which frames of
// a long sequence get one.
#include "icef/app/track_app.h"

#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <vector>

namespace icef {
namespace {

bool IsGreen(const Image& im, int x, int y) { return im.At(x, y, 1) > 0.8f && im.At(x, y, 0) < 0.3f; }
bool IsRed(const Image& im, int x, int y) { return im.At(x, y, 0) > 0.8f && im.At(x, y, 1) < 0.3f; }

// 68 points on a circle of radius r around (cx, cy), in a frame's pixels.
std::vector<Vec2f> Circle(float cx, float cy, float r) {
  std::vector<Vec2f> p;
  for (int i = 0; i < 68; ++i) {
    const float a = 2.f * 3.14159265f * i / 68.f;
    p.emplace_back(cx + r * std::cos(a), cy + r * std::sin(a));
  }
  return p;
}

TEST(RetrackOverlay, DrawsLandmarksAndFitOverTheFrameOnItsBackground) {
  // A 64x32 RGBA frame: transparent, so the overlay shows the background (blue).
  Image frame(64, 32, 4);
  const Vec3f background(0.f, 0.f, 1.f);
  const std::vector<Vec2f> landmarks = Circle(16, 16, 8);  // left half of the frame
  const std::vector<Vec2f> fitted = Circle(48, 16, 8);     // right half
  const Image out = RetrackOverlay(frame, background, landmarks, fitted);
  ASSERT_EQ(out.height, 384);
  ASSERT_EQ(out.width, 768);  // aspect kept
  ASSERT_EQ(out.channels, 3);
  const double s = 384.0 / 32;
  // Background where nothing is drawn.
  EXPECT_FLOAT_EQ(out.At(5, 5, 2), 1.f);
  EXPECT_FLOAT_EQ(out.At(5, 5, 0), 0.f);
  // Every landmark is a green dot at its scaled position; the fit draws red only on the right half.
  for (const Vec2f& l : landmarks)
    EXPECT_TRUE(IsGreen(out, int(std::floor(l.x() * s)), int(std::floor(l.y() * s))));
  int red_left = 0, red_right = 0;
  for (int y = 0; y < out.height; ++y)
    for (int x = 0; x < out.width; ++x)
      if (IsRed(out, x, y)) ++(x < out.width / 2 ? red_left : red_right);
  EXPECT_EQ(red_left, 0);
  EXPECT_GT(red_right, 200);
  // An opaque frame shows its own colour, not the background.
  Image opaque(64, 32, 3);
  for (int y = 0; y < 32; ++y)
    for (int x = 0; x < 64; ++x) opaque.At(x, y, 0) = 0.5f;
  const Image o2 = RetrackOverlay(opaque, background, {}, {});
  EXPECT_NEAR(o2.At(100, 100, 0), 0.5f, 1e-5f);
  EXPECT_NEAR(o2.At(100, 100, 2), 0.f, 1e-5f);
}

TEST(RetrackOverlay, LongSequencesGetOverlaysSpreadFromFirstToLast) {
  const std::vector<int> few = RetrackOverlayFrames(38);
  ASSERT_EQ(few.size(), 38u);
  for (int i = 0; i < 38; ++i) EXPECT_EQ(few[i], i);
  const std::vector<int> many = RetrackOverlayFrames(5000);
  ASSERT_EQ(static_cast<int>(many.size()), kMaxRetrackOverlays);
  EXPECT_EQ(many.front(), 0);
  EXPECT_EQ(many.back(), 4999);
  for (size_t i = 1; i < many.size(); ++i) {
    EXPECT_GT(many[i], many[i - 1]);
    EXPECT_NEAR(many[i] - many[i - 1], 4999.0 / 99, 1.0);
  }
  EXPECT_TRUE(RetrackOverlayFrames(0).empty());
}

// icef track's options: the named choices parsed, the ones not given at the mode's defaults.
TEST(TrackCommand, PhotosKeepTheTrackDefaults) {
  TrackCommandOptions c;
  c.segmentation = "none";
  c.silhouette_region = "head";
  c.detector = "dlib";
  const Result<TrackAppOptions> o = ResolveTrackOptions(c);
  ASSERT_TRUE(o.ok()) << o.status().message();
  const track::TrackOptions d;
  EXPECT_EQ(o->track.segmentation, track::TrackOptions::Segmentation::kNone);
  EXPECT_FALSE(o->track.fit.silhouette_face_only);
  EXPECT_EQ(o->track.fit.detector, track::LandmarkDetector::kDlib);
  EXPECT_EQ(o->track.silhouette_points, d.silhouette_points);
  EXPECT_EQ(o->track.fit.photometric_weight, d.fit.photometric_weight);
  EXPECT_EQ(o->track.fit.landmark_sigma_iod, d.fit.landmark_sigma_iod);
  EXPECT_FALSE(o->track.focal.has_value());
  EXPECT_TRUE(o->fit_style);
}

TEST(TrackCommand, KeepCamerasTakesTheRetrackDefaultsUnlessGiven) {
  TrackCommandOptions c;
  c.app.keep_cameras = true;
  c.landmarks = "model";
  c.generic_style = true;
  c.silhouette_points = 7;
  c.focal = 900;
  const Result<TrackAppOptions> o = ResolveTrackOptions(c);
  ASSERT_TRUE(o.ok()) << o.status().message();
  const track::RetrackOptions r;
  EXPECT_EQ(o->landmarks, track::RetrackLandmarks::kDatasetModel);
  EXPECT_FALSE(o->fit_style);
  EXPECT_EQ(o->track.silhouette_points, 7);  // given
  EXPECT_EQ(o->track.fit.photometric_weight, r.fit.photometric_weight);
  EXPECT_EQ(o->track.fit.landmark_sigma_iod, r.fit.landmark_sigma_iod);
  EXPECT_EQ(o->track.focal, 900.0);
}

TEST(TrackCommand, BadChoicesNameTheOption) {
  TrackCommandOptions c;
  c.landmarks = "eyes";
  EXPECT_NE(ResolveTrackOptions(c).status().message().find("--landmarks"), std::string::npos);
  c.landmarks = "model";
  c.generic_style = true;  // without --keep-cameras
  EXPECT_NE(ResolveTrackOptions(c).status().message().find("--generic-style"), std::string::npos);
  TrackCommandOptions model;
  model.face_model = "flame";
  EXPECT_NE(ResolveTrackOptions(model).status().message().find("--face-model: expected procedural or ict"),
            std::string::npos);
  model.face_model = "ict";
  ASSERT_TRUE(ResolveTrackOptions(model).ok());
  EXPECT_EQ(ResolveTrackOptions(model)->track.face_model, track::TrackFaceModel::kIct);
  model.app.keep_cameras = true;  // a dataset re-expressed in ICT with its cameras held
  ASSERT_TRUE(ResolveTrackOptions(model).ok());
  EXPECT_EQ(ResolveTrackOptions(model)->track.face_model, track::TrackFaceModel::kIct);
  // The procedural fit's refinements are refused with ICT, which fits the landmarks alone.
  for (const bool keep : {true, false}) {
    TrackCommandOptions refine = model;
    refine.app.keep_cameras = keep;
    refine.silhouette_points = 100;
    EXPECT_NE(ResolveTrackOptions(refine).status().message().find("--silhouette-points"), std::string::npos);
    refine.silhouette_points.reset();
    refine.photometric_weight = 4.0;
    EXPECT_FALSE(ResolveTrackOptions(refine).ok());
    refine.photometric_weight.reset();
    refine.landmarks = "model";
    refine.generic_style = true;
    EXPECT_NE(ResolveTrackOptions(refine).status().message().find("landmarks alone"), std::string::npos);
  }
  TrackCommandOptions none;  // nothing to track
  EXPECT_NE(RunTrackCommand(none, std::cout, std::cerr).message().find("give the photos"), std::string::npos);
}

}  // namespace
}  // namespace icef
