#include "icef/landmarks/face_landmark_detector.h"

#include <gtest/gtest.h>

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
  const Image rgba = synth::RenderGroundTruth(head, camera, std::vector<float>(face::kNumExpressions, 0.f),
                                              Executor(2));
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

}  // namespace
}  // namespace icef
