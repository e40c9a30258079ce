#include "icef/eval/face_descriptor.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>

#include "icef/eval/face_identity.h"
#include "icef/infer/cnn_test_util.h"

namespace icef::eval {
namespace {

using namespace ::icef::infer::testing;
namespace fs = std::filesystem;

ConvAffine RandomConvAffine(int cin, int cout, uint64_t item) {
  ConvAffine layer;
  layer.conv = RandomConv(3, 3, cin, cout, true, item);
  Rng rng(3, StreamId("face_descriptor_test_affine"), 0, item);
  for (int o = 0; o < cout; ++o) {
    layer.scale.push_back(float(rng.Uniform(0.5, 1.5)));
    layer.shift.push_back(float(rng.Uniform(-0.2, 0.2)));
  }
  return layer;
}

infer::Tensor3 NaiveAffine(infer::Tensor3 x, const ConvAffine& l, bool relu) {
  for (int y = 0; y < x.h; ++y)
    for (int i = 0; i < x.w; ++i)
      for (int c = 0; c < x.c; ++c) {
        const double v = double(x.At(y, i, c)) * l.scale[c] + l.shift[c];
        x.At(y, i, c) = float(relu ? std::max(v, 0.0) : v);
      }
  return x;
}

TEST(FaceDescriptorTest, ResidualBlockMatchesNaiveReference) {
  const infer::Tensor3 x = RandomTensor(7, 7, 4, 100);
  ResidualBlockWeights w{RandomConvAffine(4, 4, 101), RandomConvAffine(4, 4, 102)};
  infer::Tensor3 ref = NaiveAffine(NaiveConv(x, w.conv1.conv, 1, infer::Padding::Uniform(1)), w.conv1, true);
  ref = NaiveAffine(NaiveConv(ref, w.conv2.conv, 1, infer::Padding::Uniform(1)), w.conv2, false);
  for (size_t i = 0; i < ref.data.size(); ++i) ref.data[i] = std::max(ref.data[i] + x.data[i], 0.f);
  ExpectNear(ResidualBlock(x, w, false), ref, 1e-4);
}

TEST(FaceDescriptorTest, DownBlockMatchesNaiveReference) {
  // 8x8 input: the stride-2 valid conv gives 3x3, the 2x2 average pool 4x4, so the conv branch is
  // zero-padded at the bottom/right, and the shortcut's channels 3..5 are zero (as in conv256_down).
  for (int size : {8, 9, 7}) {
    SCOPED_TRACE("input " + std::to_string(size));
    const infer::Tensor3 x = RandomTensor(size, size, 3, 110 + size);
    ResidualBlockWeights w{RandomConvAffine(3, 6, 111), RandomConvAffine(6, 6, 112)};
    infer::Tensor3 branch =
        NaiveAffine(NaiveConv(x, w.conv1.conv, 2, infer::Padding::Valid()), w.conv1, true);
    branch = NaiveAffine(NaiveConv(branch, w.conv2.conv, 1, infer::Padding::Uniform(1)), w.conv2, false);
    const int ph = size / 2;
    infer::Tensor3 ref(ph, ph, 6);
    for (int y = 0; y < ph; ++y)
      for (int i = 0; i < ph; ++i)
        for (int c = 0; c < 6; ++c) {
          double v = 0.0;
          if (c < 3)
            v += 0.25 * (double(x.At(2 * y, 2 * i, c)) + x.At(2 * y + 1, 2 * i, c) +
                         x.At(2 * y, 2 * i + 1, c) + x.At(2 * y + 1, 2 * i + 1, c));
          if (y < branch.h && i < branch.w) v += branch.At(y, i, c);
          ref.At(y, i, c) = float(std::max(v, 0.0));
        }
    ExpectNear(ResidualBlock(x, w, true), ref, 1e-4);
  }
}

TEST(FaceDescriptorTest, DistanceAndCosine) {
  FaceDescriptor a{}, b{};
  a[0] = 3.f;
  b[0] = 3.f;
  b[1] = 4.f;
  EXPECT_DOUBLE_EQ(DescriptorDistance(a, b), 4.0);
  EXPECT_DOUBLE_EQ(DescriptorCosine(a, b), 0.6);
  EXPECT_DOUBLE_EQ(DescriptorCosine(a, a), 1.0);
  EXPECT_DOUBLE_EQ(DescriptorDistance(a, a), 0.0);
}

TEST(FaceDescriptorTest, MissingTensorsAndMissingFilesAreErrors) {
  const fs::path dir = fs::path(::testing::TempDir()) / "icef_tfjs_tiny";
  const Result<infer::TensorMap> good = infer::ReadTfjsWeights(WriteTinyTfjs(dir));
  ASSERT_TRUE(good.ok());
  const Result<FaceDescriptorNet> net = FaceDescriptorNet::FromTensors(*good, "tiny");
  ASSERT_FALSE(net.ok());
  EXPECT_NE(net.status().message().find("conv32_down/conv/filters"), std::string::npos);
  const Result<FaceDescriptorNet> missing = FaceDescriptorNet::Load(dir / "nowhere");
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(missing.status().message().find("install-deps"), std::string::npos);
}

// --- The real network on real photos installed by Debian packages (scripts/install-deps.sh). ---

constexpr const char* kHaar =
    "/usr/share/doc/opencv-doc/opencv4/html/Cascade_Classifier_Tutorial_Result_Haar.jpg";
constexpr const char* kLbp =
    "/usr/share/doc/opencv-doc/opencv4/html/Cascade_Classifier_Tutorial_Result_LBP.jpg";
constexpr const char* kAstronaut = "/usr/lib/python3/dist-packages/skimage/data/astronaut.png";
constexpr const char* kHopper = "/usr/share/matplotlib/mpl-data/sample_data/grace_hopper.jpg";

TEST(FaceDescriptorRealTest, SamePersonUnderThresholdDifferentPeopleOver) {
  const fs::path model = ResolveFaceIdModelDir();
  if (!fs::exists(model / kFaceIdManifestName)) GTEST_SKIP() << "face-id model not installed at " << model;
  if (!fs::exists(kDefaultShapePredictorPath)) GTEST_SKIP() << "libdlib-data not installed";
  for (const char* photo : {kHaar, kLbp, kAstronaut, kHopper})
    if (!fs::exists(photo)) GTEST_SKIP() << "photo not installed: " << photo;

  Result<FaceIdentity> identity = FaceIdentity::Load({});
  ASSERT_TRUE(identity.ok()) << identity.status().message();
  std::vector<FaceDescriptor> d;
  for (const char* photo : {kHaar, kLbp, kAstronaut, kHopper}) {
    const Result<Image> image = ReadImage(photo);
    ASSERT_TRUE(image.ok()) << image.status().message();
    const Result<FaceIdentityResult> r = identity->Describe(*image, std::nullopt);
    ASSERT_TRUE(r.ok()) << photo << ": " << r.status().message();
    EXPECT_TRUE(r->detected);
    d.push_back(r->descriptor);
  }
  // Two webcam frames of the same woman.
  const double same = DescriptorDistance(d[0], d[1]);
  std::cout << "same person (opencv Haar/LBP frames): distance " << same << ", cosine "
            << DescriptorCosine(d[0], d[1]) << "\n";
  EXPECT_LT(same, kSamePersonThreshold);
  for (auto [i, j] : {std::pair{0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}}) {
    const double dist = DescriptorDistance(d[i], d[j]);
    std::cout << "different people " << i << "-" << j << ": distance " << dist << ", cosine "
              << DescriptorCosine(d[i], d[j]) << "\n";
    EXPECT_GT(dist, kSamePersonThreshold) << i << "-" << j;
  }
}

TEST(FaceDescriptorRealTest, DatasetLandmarksGiveTheDetectorsChipAndSpeedIsBounded) {
  const fs::path model = ResolveFaceIdModelDir();
  if (!fs::exists(model / kFaceIdManifestName)) GTEST_SKIP() << "face-id model not installed at " << model;
  if (!fs::exists(kDefaultShapePredictorPath)) GTEST_SKIP() << "libdlib-data not installed";
  if (!fs::exists(kAstronaut)) GTEST_SKIP() << "photo not installed: " << kAstronaut;
  Result<FaceIdentity> identity = FaceIdentity::Load({});
  ASSERT_TRUE(identity.ok()) << identity.status().message();
  const Result<Image> image = ReadImage(kAstronaut);
  ASSERT_TRUE(image.ok());
  const Result<FaceIdentityResult> detected = identity->Describe(*image, std::nullopt);
  ASSERT_TRUE(detected.ok()) << detected.status().message();
  // Passing the detector's landmarks as if they came from a dataset gives the same descriptor.
  const Result<FaceIdentityResult> given = identity->Describe(*image, detected->landmarks);
  ASSERT_TRUE(given.ok()) << given.status().message();
  EXPECT_FALSE(given->detected);
  EXPECT_EQ(given->descriptor, detected->descriptor);
  // Landmarks of another face (shifted by 40 px) give a different chip and descriptor.
  std::vector<Vec2f> shifted = detected->landmarks;
  for (Vec2f& p : shifted) p.x() += 40.f;
  const Result<FaceIdentityResult> moved = identity->Describe(*image, shifted);
  ASSERT_TRUE(moved.ok());
  EXPECT_GT(DescriptorDistance(moved->descriptor, detected->descriptor), 0.05);

  const int runs = 10;
  const auto t0 = std::chrono::steady_clock::now();
  for (int i = 0; i < runs; ++i) EXPECT_EQ(identity->net().Compute(detected->chip), detected->descriptor);
  const double ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count() / runs;
  std::cout << "face descriptor network: " << ms << " ms per 150x150 chip\n";
  EXPECT_LT(ms, 1000.0);
}

}  // namespace
}  // namespace icef::eval
