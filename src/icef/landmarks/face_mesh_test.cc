#include "icef/landmarks/face_mesh.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <set>

#include "icef/landmarks/face_landmark_detector.h"

namespace icef {
namespace {

namespace fs = std::filesystem;

constexpr const char* kHopper = "/usr/share/matplotlib/mpl-data/sample_data/grace_hopper.jpg";
constexpr const char* kAstronaut = "/usr/lib/python3/dist-packages/skimage/data/astronaut.png";

TEST(FaceMeshTest, Ibug68IndexNamesDistinctMeshVertices) {
  const auto& index = FaceMesh::Ibug68Index();
  std::set<int> seen(index.begin(), index.end());
  EXPECT_EQ(seen.size(), 68u);
  for (int i : index) EXPECT_TRUE(i >= 0 && i < FaceMesh::kPoints) << i;
}

TEST(FaceMeshTest, RoiIsTheTurnedBoundingBoxScaled) {
  // A 40 x 20 rectangle turned by 30 degrees about (100, 50).
  const float a = float(M_PI / 6);
  std::vector<Vec2f> points;
  for (float u : {-20.f, 20.f})
    for (float v : {-10.f, 10.f})
      points.push_back(
          Vec2f(100 + std::cos(a) * u - std::sin(a) * v, 50 + std::sin(a) * u + std::cos(a) * v));
  Vec2f center;
  float size = 0, angle = 0;
  FaceMeshRoi(points, Vec2f(0, 0), Vec2f(std::cos(a), std::sin(a)), 1.5f, center, size, angle);
  EXPECT_NEAR(angle, a, 1e-6);
  EXPECT_NEAR(center.x(), 100, 1e-4);
  EXPECT_NEAR(center.y(), 50, 1e-4);
  EXPECT_NEAR(size, 60, 1e-4);
}

// On real photos the mesh finds the face dlib finds: a confident face score, and the 68 points it
// stands for within a small fraction of the inter-ocular distance of dlib's (the two conventions
// differ most along the jaw line).
TEST(FaceMeshTest, AgreesWithDlibOnRealPhotos) {
  auto mesh = FaceMesh::Load();
  if (!mesh.ok()) GTEST_SKIP() << mesh.status().message();
  if (!fs::exists(kDefaultShapePredictorPath)) GTEST_SKIP() << "libdlib-data not installed";
  auto detector = FaceLandmarkDetector::Load();
  ASSERT_TRUE(detector.ok()) << detector.status().message();
  for (const char* photo : {kHopper, kAstronaut}) {
    if (!fs::exists(photo)) GTEST_SKIP() << "photo not installed: " << photo;
    auto image = ReadImage(photo);
    ASSERT_TRUE(image.ok()) << image.status().message();
    auto face = detector->DetectFace(*image, true);
    ASSERT_TRUE(face.ok()) << face.status().message();
    auto result = mesh->Run(*image, face->landmarks);
    ASSERT_TRUE(result.ok()) << result.status().message();
    EXPECT_GT(result->face_score, 0.9f) << photo;
    Vec2f eye_r = Vec2f::Zero(), eye_l = Vec2f::Zero();
    for (int i = 36; i < 42; ++i) eye_r += face->landmarks[i] / 6.f;
    for (int i = 42; i < 48; ++i) eye_l += face->landmarks[i] / 6.f;
    const float iod = (eye_l - eye_r).norm();
    std::vector<float> inner;  // brows, nose, eyes, mouth: 17..67
    for (int i = 17; i < 68; ++i) inner.push_back((result->landmarks[i] - face->landmarks[i]).norm() / iod);
    std::sort(inner.begin(), inner.end());
    const float median = inner[inner.size() / 2];
    EXPECT_LT(median, 0.1f) << photo;
    std::printf("%s: face score %.3f, median distance to dlib's landmarks %.3f IOD (worst %.3f)\n", photo,
                result->face_score, median, inner.back());
  }
}

// A crop without a face scores low: the fish of opencv-doc, cropped where a face would be.
TEST(FaceMeshTest, ACropWithoutAFaceScoresLow) {
  auto mesh = FaceMesh::Load();
  if (!mesh.ok()) GTEST_SKIP() << mesh.status().message();
  const char* fish = "/usr/share/doc/opencv-doc/examples/data/HappyFish.jpg";
  if (!fs::exists(fish)) GTEST_SKIP() << "photo not installed: " << fish;
  auto image = ReadImage(fish);
  ASSERT_TRUE(image.ok()) << image.status().message();
  auto result = mesh->RunCrop(*image, Vec2f(image->width * 0.5f, image->height * 0.5f),
                              0.8f * std::min(image->width, image->height), 0.f);
  ASSERT_TRUE(result.ok()) << result.status().message();
  EXPECT_LT(result->face_score, FaceMesh::kMinFaceScore);
}

TEST(FaceMeshTest, MissingModelIsAnErrorNamingTheFile) {
  auto mesh = FaceMesh::Load(fs::path(::testing::TempDir()) / "icef_no_facemesh");
  ASSERT_FALSE(mesh.ok());
  EXPECT_NE(mesh.status().message().find("facemesh.json"), std::string::npos) << mesh.status().message();
}

}  // namespace
}  // namespace icef
