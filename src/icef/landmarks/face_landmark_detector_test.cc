#include "icef/landmarks/face_landmark_detector.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "icef/face/expression.h"
#include "icef/synth/ground_truth_renderer.h"
#include "icef/synth/head_model.h"
#include "icef/synth/synthesize.h"

namespace icef {
namespace {

namespace fs = std::filesystem;

TEST(FaceLandmarkDetector, MissingPredictorIsAClearError) {
  const Result<FaceLandmarkDetector> detector = FaceLandmarkDetector::Load("/nonexistent/predictor.dat");
  ASSERT_FALSE(detector.ok());
  EXPECT_NE(detector.status().message().find("/nonexistent/predictor.dat"), std::string::npos);
  EXPECT_NE(detector.status().message().find("libdlib-data"), std::string::npos);
}

TEST(FaceLandmarkDetector, BlankImageHasNoFace) {
  if (!fs::exists(kDefaultShapePredictorPath)) GTEST_SKIP() << "libdlib-data not installed";
  const FaceLandmarkDetector detector = FaceLandmarkDetector::Load().value();
  const Result<FaceDetection> face = detector.DetectFace(Image(120, 100, 3, 1.f));
  ASSERT_FALSE(face.ok());
  EXPECT_EQ(face.status().message(), "no face found");
  EXPECT_FALSE(detector.DetectFace(Image()).ok());
}

// The synthetic head, frontal at 160x160: one face, landmarks inside (a margin around) its box,
// and a clone gives the same answer as the original.
TEST(FaceLandmarkDetector, FindsTheSyntheticHeadAndClonesAgree) {
  if (!fs::exists(kDefaultShapePredictorPath)) GTEST_SKIP() << "libdlib-data not installed";
  const synth::HeadModel head(synth::IdentityParams::FromSeed(1));
  Intrinsics k;
  k.width = k.height = 160;
  k.fl_x = k.fl_y = 3.6 * 160;
  k.cx = k.cy = 80;
  const Camera camera = synth::OrbitCamera(k, 3.5, 0, 0);
  const Image rgba =
      synth::RenderGroundTruth(head, camera, std::vector<float>(face::kNumExpressions, 0.f), Executor(2));
  const Image rgb = CompositeOver(rgba, Vec3f::Ones());
  const FaceLandmarkDetector detector = FaceLandmarkDetector::Load().value();
  const Result<FaceDetection> face = detector.DetectFace(rgb);
  ASSERT_TRUE(face.ok()) << face.status().ToString();
  EXPECT_EQ(face->num_faces, 1);
  ASSERT_EQ(face->landmarks.size(), 68u);
  const Vec2f margin = 0.25f * (face->box_max - face->box_min);
  for (const Vec2f& p : face->landmarks) {
    EXPECT_GT(p.x(), face->box_min.x() - margin.x());
    EXPECT_LT(p.x(), face->box_max.x() + margin.x());
    EXPECT_GT(p.y(), face->box_min.y() - margin.y());
    EXPECT_LT(p.y(), face->box_max.y() + margin.y());
  }
  // iBUG layout: the nose tip (30) lies between the outer eye corners (36, 45) and above the
  // mouth's lower lip (57).
  const auto& l = face->landmarks;
  EXPECT_LT(l[36].x(), l[30].x());
  EXPECT_LT(l[30].x(), l[45].x());
  EXPECT_LT(l[30].y(), l[57].y());
  const Result<FaceDetection> again = detector.Clone().DetectFace(rgb);
  ASSERT_TRUE(again.ok());
  EXPECT_EQ(again->landmarks, face->landmarks);
}

TEST(FaceLandmarkDetector, MirrorIndexSwapsSidesAndKeepsTheMidline) {
  const std::array<int, 68>& m = FaceLandmarkDetector::MirrorIndex();
  std::vector<int> midline;
  for (int i = 0; i < 68; ++i) {
    EXPECT_EQ(m[m[i]], i) << i;
    if (m[i] == i) midline.push_back(i);
  }
  EXPECT_EQ(midline, (std::vector<int>{8, 27, 28, 29, 30, 33, 51, 57, 62, 66}));
  EXPECT_EQ(m[0], 16);
  EXPECT_EQ(m[17], 26);
  EXPECT_EQ(m[31], 35);
  EXPECT_EQ(m[36], 45);
  EXPECT_EQ(m[39], 42);
  EXPECT_EQ(m[41], 46);
  EXPECT_EQ(m[48], 54);
  EXPECT_EQ(m[59], 55);
  EXPECT_EQ(m[60], 64);
  EXPECT_EQ(m[67], 65);
}

Image MirrorImage(const Image& image) {
  Image out(image.width, image.height, image.channels);
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x)
      for (int c = 0; c < image.channels; ++c) out.At(image.width - 1 - x, y, c) = image.At(x, y, c);
  return out;
}

// The averaged landmarks: near one run's, sub-pixel, and mirrored with the image (a left-right
// mistake in the relabelling or the mapping back would move them by the face's width).
TEST(FaceLandmarkDetector, AveragedLandmarksFollowTheMirroredImage) {
  if (!fs::exists(kDefaultShapePredictorPath)) GTEST_SKIP() << "libdlib-data not installed";
  const synth::HeadModel head(synth::IdentityParams::FromSeed(2));
  Intrinsics k;
  k.width = 200;
  k.height = 240;
  k.fl_x = k.fl_y = 3.6 * 240;
  k.cx = 100;
  k.cy = 120;
  const Camera camera = synth::OrbitCamera(k, 3.5, 15, 5);
  std::vector<float> expression(face::kNumExpressions, 0.f);
  expression[face::kSmileLeft] = 0.8f;
  const Image rgb =
      CompositeOver(synth::RenderGroundTruth(head, camera, expression, Executor(2)), Vec3f::Ones());
  const FaceLandmarkDetector detector = FaceLandmarkDetector::Load().value();
  const Result<FaceDetection> one = detector.DetectFace(rgb);
  const Result<FaceDetection> avg = detector.DetectFace(rgb, /*averaged=*/true);
  const Result<FaceDetection> avg_mirror = detector.DetectFace(MirrorImage(rgb), /*averaged=*/true);
  ASSERT_TRUE(one.ok() && avg.ok() && avg_mirror.ok());
  EXPECT_EQ(avg->box_min, one->box_min);
  const float width = one->box_max.x() - one->box_min.x();
  int sub_pixel = 0;
  double mirror_err = 0;
  for (int i = 0; i < 68; ++i) {
    EXPECT_LT((avg->landmarks[i] - one->landmarks[i]).norm(), 0.06f * width) << i;
    const float fx = avg->landmarks[i].x() - std::floor(avg->landmarks[i].x());
    sub_pixel += std::abs(fx - 0.5f) > 1e-3f;
    const Vec2f back = avg_mirror->landmarks[FaceLandmarkDetector::MirrorIndex()[i]];
    mirror_err += (Vec2f(float(k.width) - back.x(), back.y()) - avg->landmarks[i]).squaredNorm();
  }
  EXPECT_GT(sub_pixel, 34);  // one run's landmarks all sit on pixel centres
  EXPECT_LT(std::sqrt(mirror_err / 68), 0.02 * width);
}

}  // namespace
}  // namespace icef
