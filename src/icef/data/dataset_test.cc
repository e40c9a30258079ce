#include "icef/data/dataset.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <map>

#include "icef/io/atomic_file.h"
#include "icef/io/json_util.h"
#include "icef/testing/tiny_dataset.h"

namespace icef {
namespace {

namespace fs = std::filesystem;
using testing::MakeTempDir;
using testing::TinyDatasetOptions;
using testing::WriteTinyDataset;

std::string TestName() { return ::testing::UnitTest::GetInstance()->current_test_info()->name(); }

// Every file under dir with its bytes, to check that a failed load touched nothing.
std::map<std::string, std::string> Snapshot(const fs::path& dir) {
  std::map<std::string, std::string> files;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    if (e.is_regular_file()) files[e.path().string()] = ReadFile(e.path()).value();
  return files;
}

void EditJson(const fs::path& file, const std::function<void(Json&)>& edit) {
  Json doc = ReadJsonFile(file).value();
  edit(doc);
  ASSERT_TRUE(WriteFileAtomic(file, doc.dump(2)).ok());
}

// Loads `dir`, expects failure with `expected` in the message, a one-line message, and no file changed.
void ExpectLoadError(const fs::path& dir, const std::string& expected) {
  const auto before = Snapshot(dir);
  const Result<Dataset> result = LoadDataset(dir);
  ASSERT_FALSE(result.ok()) << "expected an error containing: " << expected;
  const std::string message = result.status().message();
  EXPECT_NE(message.find(expected), std::string::npos) << message;
  EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  EXPECT_EQ(Snapshot(dir), before);
}

void ExpectSameFrames(const std::vector<Frame>& a, const std::vector<Frame>& b) {
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].file_path, b[i].file_path);
    EXPECT_EQ(a[i].expression, b[i].expression);
    EXPECT_EQ(a[i].camera.world_from_cam(), b[i].camera.world_from_cam());
    const Intrinsics &ka = a[i].camera.intrinsics(), &kb = b[i].camera.intrinsics();
    EXPECT_EQ(ka.width, kb.width);
    EXPECT_EQ(ka.height, kb.height);
    EXPECT_EQ(ka.fl_x, kb.fl_x);
    EXPECT_EQ(ka.fl_y, kb.fl_y);
    EXPECT_EQ(ka.cx, kb.cx);
    EXPECT_EQ(ka.cy, kb.cy);
    EXPECT_EQ(a[i].landmarks_2d.has_value(), b[i].landmarks_2d.has_value());
    if (a[i].landmarks_2d && b[i].landmarks_2d) {
      EXPECT_EQ(*a[i].landmarks_2d, *b[i].landmarks_2d);
    }
    EXPECT_EQ(a[i].landmarks_2d_visible, b[i].landmarks_2d_visible);
    EXPECT_EQ(a[i].landmarks_3d.has_value(), b[i].landmarks_3d.has_value());
    if (a[i].landmarks_3d && b[i].landmarks_3d) {
      EXPECT_EQ(*a[i].landmarks_3d, *b[i].landmarks_3d);
    }
    EXPECT_EQ(a[i].delta, b[i].delta);
    EXPECT_EQ(a[i].tier, b[i].tier);
    EXPECT_EQ(a[i].neutral_file_path, b[i].neutral_file_path);
    EXPECT_EQ(a[i].neutral_landmarks_2d, b[i].neutral_landmarks_2d);
    EXPECT_EQ(a[i].neutral_landmarks_3d, b[i].neutral_landmarks_3d);
    EXPECT_EQ(a[i].bbox, b[i].bbox);
  }
}

void ExpectSameDataset(const Dataset& a, const Dataset& b) {
  EXPECT_EQ(a.aabb.min, b.aabb.min);
  EXPECT_EQ(a.aabb.max, b.aabb.max);
  EXPECT_EQ(a.expression_dim, b.expression_dim);
  EXPECT_EQ(a.expression_names, b.expression_names);
  EXPECT_EQ(a.background, b.background);
  EXPECT_EQ(a.background_file_path, b.background_file_path);
  EXPECT_EQ(a.tier_thresholds, b.tier_thresholds);
  ExpectSameFrames(a.train, b.train);
  ExpectSameFrames(a.test, b.test);
  ExpectSameFrames(a.val, b.val);
}

TEST(Dataset, LoadsWhatTheFixtureWrote) {
  const fs::path dir = MakeTempDir(TestName());
  TinyDatasetOptions options;
  options.landmarks_3d = true;
  options.num_val = 1;
  const Dataset written = WriteTinyDataset(dir, options);
  const Dataset loaded = LoadDataset(dir).value();
  EXPECT_EQ(loaded.root, dir);
  ASSERT_EQ(loaded.train.size(), 3u);
  ASSERT_EQ(loaded.test.size(), 2u);
  ASSERT_EQ(loaded.val.size(), 1u);
  EXPECT_EQ(loaded.expression_dim, 4);
  EXPECT_EQ(loaded.expression_names, (std::vector<std::string>{"e0", "e1", "e2", "e3"}));
  EXPECT_EQ(loaded.test[0].tier, Tier::kObserved);
  EXPECT_EQ(loaded.test[0].delta, 0.0);
  EXPECT_TRUE(loaded.test[1].tier.has_value());
  ExpectSameDataset(written, loaded);
  EXPECT_EQ(loaded.train[1].camera.width(), 8);
  const Image image = LoadFrameImage(loaded, loaded.train[1]).value();
  EXPECT_EQ(image.width, 8);
  EXPECT_EQ(image.height, 6);
}

TEST(Dataset, SaveLoadRoundTripIsExactAndStable) {
  const fs::path dir = MakeTempDir(TestName());
  TinyDatasetOptions options;
  options.landmarks_3d = true;
  WriteTinyDataset(dir, options);
  Dataset first = LoadDataset(dir).value();
  // Fields the fixture does not set: per-frame intrinsics, visibility, neutral image, bbox, image background.
  first.train[2].camera =
      Camera(Intrinsics{8, 6, 11.25, 10.5, 4.25, 2.75}, first.train[2].camera.world_from_cam());
  first.train[0].landmarks_2d_visible = std::vector<bool>(kNumLandmarks, true);
  (*first.train[0].landmarks_2d_visible)[5] = false;
  first.test[1].neutral_file_path = first.train[1].file_path;
  first.test[1].neutral_landmarks_2d = first.train[1].landmarks_2d;
  first.test[1].neutral_landmarks_3d = first.train[1].landmarks_3d;
  first.train[1].bbox = std::array<float, 4>{0.1f, 0.9f, 0.2f, 0.8f};
  first.background_file_path = first.train[0].file_path;
  first.background = Vec3f(0.25f, 0.5f, 0.125f);
  ASSERT_TRUE(SaveDataset(first).ok());
  const std::string json_before = ReadFile(dir / "transforms_train.json").value();
  const Dataset second = LoadDataset(dir).value();
  ExpectSameDataset(first, second);
  ASSERT_TRUE(SaveDataset(second).ok());
  EXPECT_EQ(ReadFile(dir / "transforms_train.json").value(), json_before);
  EXPECT_FALSE(fs::exists(dir / "transforms_val.json"));  // val only when non-empty
}

TEST(Dataset, SaveRejectsInconsistentDatasetsAndWritesNothing) {
  const fs::path dir = MakeTempDir(TestName());
  Dataset d = WriteTinyDataset(dir);
  const auto before = Snapshot(dir);
  d.train[1].expression.pop_back();
  const Status status = SaveDataset(d);
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("train[1].expression"), std::string::npos) << status.message();
  EXPECT_EQ(Snapshot(dir), before);
}

TEST(Dataset, MissingImage) {
  const fs::path dir = MakeTempDir(TestName());
  WriteTinyDataset(dir);
  fs::remove(dir / "images" / "train_001.png");
  ExpectLoadError(dir, "transforms_train.json: frames[1].file_path: image not found: ");
}

TEST(Dataset, UnreadableImage) {
  const fs::path dir = MakeTempDir(TestName());
  WriteTinyDataset(dir);
  ASSERT_TRUE(WriteFileAtomic(dir / "images" / "test_001.png", "not a png").ok());
  ExpectLoadError(dir, "transforms_test.json: frames[1].file_path: ");
}

TEST(Dataset, NonRigidTransform) {
  const fs::path dir = MakeTempDir(TestName());
  WriteTinyDataset(dir);
  EditJson(dir / "transforms_train.json", [](Json& d) {
    for (int r = 0; r < 3; ++r)
      d["frames"][2]["transform_matrix"][r][0] = 2.0 * d["frames"][2]["transform_matrix"][r][0].get<double>();
  });
  ExpectLoadError(dir, "transforms_train.json: frames[2].transform_matrix: rotation is not orthonormal");
}

TEST(Dataset, ReflectionAndBadLastRowAreNotRigid) {
  const fs::path dir = MakeTempDir(TestName());
  WriteTinyDataset(dir);
  EditJson(dir / "transforms_train.json", [](Json& d) {
    for (int r = 0; r < 3; ++r)
      d["frames"][0]["transform_matrix"][r][0] = -d["frames"][0]["transform_matrix"][r][0].get<double>();
  });
  ExpectLoadError(dir, "transforms_train.json: frames[0].transform_matrix: rotation has determinant -1");
  WriteTinyDataset(dir);
  EditJson(dir / "transforms_train.json", [](Json& d) { d["frames"][0]["transform_matrix"][3][0] = 0.5; });
  ExpectLoadError(dir, "transforms_train.json: frames[0].transform_matrix: last row must be [0, 0, 0, 1]");
}

TEST(Dataset, NonFiniteTransform) {
  const fs::path dir = MakeTempDir(TestName());
  WriteTinyDataset(dir);
  // Python's json.dump writes NaN literally.
  EditJson(dir / "transforms_train.json",
           [](Json& d) { d["frames"][1]["transform_matrix"][0][3] = "@NAN@"; });
  std::string text = ReadFile(dir / "transforms_train.json").value();
  text.replace(text.find("\"@NAN@\""), 7, "NaN");
  ASSERT_TRUE(WriteFileAtomic(dir / "transforms_train.json", text).ok());
  ExpectLoadError(dir, "transforms_train.json: frames[1].transform_matrix: non-finite value NaN at [0][3]");
}

TEST(Dataset, WrongExpressionLength) {
  const fs::path dir = MakeTempDir(TestName());
  WriteTinyDataset(dir);
  EditJson(dir / "transforms_train.json", [](Json& d) { d["frames"][2]["expression"].erase(0); });
  ExpectLoadError(
      dir, "transforms_train.json: frames[2].expression: expected an array of 4 numbers, got 3 values");
}

TEST(Dataset, MissingExpression) {
  const fs::path dir = MakeTempDir(TestName());
  WriteTinyDataset(dir);
  EditJson(dir / "transforms_test.json", [](Json& d) { d["frames"][1].erase("expression"); });
  ExpectLoadError(dir, "transforms_test.json: frames[1].expression: missing required field");
}

TEST(Dataset, WrongLandmarkCount) {
  const fs::path dir = MakeTempDir(TestName());
  TinyDatasetOptions options;
  options.landmarks_3d = true;
  WriteTinyDataset(dir, options);
  EditJson(dir / "transforms_train.json", [](Json& d) { d["frames"][0]["landmarks_2d"].erase(67); });
  ExpectLoadError(dir,
                  "transforms_train.json: frames[0].landmarks_2d: expected an array of 68 arrays of 2 "
                  "numbers, got 67 entries");
  WriteTinyDataset(dir, options);
  EditJson(dir / "transforms_train.json", [](Json& d) {
    d["frames"][1]["landmarks_3d"][4] = Json::array({1, 2});
  });
  ExpectLoadError(
      dir, "transforms_train.json: frames[1].landmarks_3d: expected an array of 68 arrays of 3 numbers");
  WriteTinyDataset(dir, options);
  EditJson(dir / "transforms_train.json",
           [](Json& d) { d["frames"][1]["landmarks_2d_visible"] = Json::array({true}); });
  ExpectLoadError(dir,
                  "transforms_train.json: frames[1].landmarks_2d_visible: expected an array of 68 booleans");
}

TEST(Dataset, UnknownTier) {
  const fs::path dir = MakeTempDir(TestName());
  WriteTinyDataset(dir);
  EditJson(dir / "transforms_test.json", [](Json& d) { d["frames"][1]["tier"] = "extreme"; });
  ExpectLoadError(dir, "transforms_test.json: frames[1].tier: unknown tier \"extreme\"");
}

TEST(Dataset, NegativeDelta) {
  const fs::path dir = MakeTempDir(TestName());
  WriteTinyDataset(dir);
  EditJson(dir / "transforms_test.json", [](Json& d) { d["frames"][0]["delta"] = -0.1; });
  ExpectLoadError(dir, "transforms_test.json: frames[0].delta: must be >= 0");
}

TEST(Dataset, WrongTypeForKnownKey) {
  const fs::path dir = MakeTempDir(TestName());
  WriteTinyDataset(dir);
  EditJson(dir / "transforms_train.json", [](Json& d) { d["w"] = "8"; });
  ExpectLoadError(dir, "transforms_train.json: w: expected a number, got a string");
  WriteTinyDataset(dir);
  EditJson(dir / "transforms_test.json", [](Json& d) { d["frames"][1]["delta"] = Json::array({0.5}); });
  ExpectLoadError(dir, "transforms_test.json: frames[1].delta: expected a number, got an array of 1");
  WriteTinyDataset(dir);
  EditJson(dir / "transforms_train.json", [](Json& d) { d["frames"] = Json::object(); });
  ExpectLoadError(dir, "transforms_train.json: frames: expected an array of objects, got an object");
  WriteTinyDataset(dir);
  EditJson(dir / "transforms_train.json", [](Json& d) { d["background"] = Json::array({1, 1}); });
  ExpectLoadError(dir, "transforms_train.json: background: expected an array of 3 numbers, got 2 values");
}

TEST(Dataset, UnknownKeysAreIgnored) {
  const fs::path dir = MakeTempDir(TestName());
  const Dataset written = WriteTinyDataset(dir);
  EditJson(dir / "transforms_train.json", [](Json& d) {
    d["aabb_scale"] = 16;
    d["frames"][0]["sharpness"] = 41.5;
    d["frames"][1]["colmap_im_id"] = Json::object({{"x", 1}});
  });
  const Result<Dataset> loaded = LoadDataset(dir);
  ASSERT_TRUE(loaded.ok()) << loaded.status().message();
  ExpectSameDataset(written, *loaded);
}

TEST(Dataset, ImageSizeMismatch) {
  const fs::path dir = MakeTempDir(TestName());
  WriteTinyDataset(dir);
  EditJson(dir / "transforms_train.json", [](Json& d) { d["w"] = 9; });
  ExpectLoadError(dir, "transforms_train.json: frames[0].file_path: image ");
  ExpectLoadError(dir, "is 8x6, but w x h is 9x6");
}

TEST(Dataset, FileLevelValuesMustAgreeAcrossSplits) {
  const fs::path dir = MakeTempDir(TestName());
  WriteTinyDataset(dir);
  EditJson(dir / "transforms_test.json", [](Json& d) { d["aabb"][1][0] = 2.0; });
  ExpectLoadError(dir, "transforms_test.json: aabb: differs from the value in ");
  WriteTinyDataset(dir);
  EditJson(dir / "transforms_test.json", [](Json& d) {
    d["expression_dim"] = 5;
    d.erase("expression_names");
  });
  ExpectLoadError(dir, "transforms_test.json: expression_dim: differs");
}

TEST(Dataset, ExpressionNamesMustMatchDim) {
  const fs::path dir = MakeTempDir(TestName());
  WriteTinyDataset(dir);
  EditJson(dir / "transforms_train.json", [](Json& d) { d["expression_names"].erase(0); });
  ExpectLoadError(dir,
                  "transforms_train.json: expression_names: expected an array of 4 strings, got 3 values");
}

TEST(Dataset, MissingTrainFileAndBadJson) {
  const fs::path dir = MakeTempDir(TestName());
  ExpectLoadError(dir, "transforms_train.json: not found");
  EXPECT_FALSE(LoadDataset(dir / "nope").ok());
  WriteTinyDataset(dir);
  ASSERT_TRUE(WriteFileAtomic(dir / "transforms_test.json", "{\"frames\": [").ok());
  ExpectLoadError(dir, "transforms_test.json: invalid JSON: ");
}

TEST(Dataset, CameraAngleX) {
  const fs::path dir = MakeTempDir(TestName());
  WriteTinyDataset(dir);
  for (const char* split : {"train", "test"}) {
    EditJson(dir / ("transforms_" + std::string(split) + ".json"), [](Json& d) {
      for (const char* key : {"w", "h", "fl_x", "fl_y", "cx", "cy"}) d.erase(key);
      d["camera_angle_x"] = 0.6;
    });
  }
  const Dataset d = LoadDataset(dir).value();
  const Intrinsics& k = d.train[1].camera.intrinsics();
  EXPECT_EQ(k.width, 8);  // from the image
  EXPECT_EQ(k.height, 6);
  EXPECT_NEAR(k.fl_x, 0.5 * 8 / std::tan(0.3), 1e-12);
  EXPECT_EQ(k.fl_y, k.fl_x);
  EXPECT_EQ(k.cx, 4.0);
  EXPECT_EQ(k.cy, 3.0);

  EditJson(dir / "transforms_train.json", [](Json& d) { d["camera_angle_y"] = 0.5; });
  const Intrinsics k2 = LoadDataset(dir).value().train[0].camera.intrinsics();
  EXPECT_NEAR(k2.fl_y, 0.5 * 6 / std::tan(0.25), 1e-12);
  EditJson(dir / "transforms_train.json", [](Json& d) { d["camera_angle_x"] = 4.0; });
  ExpectLoadError(dir, "transforms_train.json: camera_angle_x: field of view must be in (0, pi)");
}

TEST(Dataset, NoFocalLengthIsAnError) {
  const fs::path dir = MakeTempDir(TestName());
  WriteTinyDataset(dir);
  EditJson(dir / "transforms_train.json", [](Json& d) {
    d.erase("fl_x");
    d.erase("fl_y");
  });
  ExpectLoadError(dir, "transforms_train.json: frames[0].fl_x: no focal length");
}

TEST(Dataset, PerFrameIntrinsicsOverrideGlobalOnes) {
  const fs::path dir = MakeTempDir(TestName());
  WriteTinyDataset(dir);
  EditJson(dir / "transforms_train.json", [](Json& d) {
    d["frames"][1]["fl_x"] = 20.0;
    d["frames"][2]["cy"] = 2.5;
  });
  const Dataset d = LoadDataset(dir).value();
  EXPECT_EQ(d.train[0].camera.intrinsics().fl_x, 9.6);
  EXPECT_EQ(d.train[1].camera.intrinsics().fl_x, 20.0);
  EXPECT_EQ(d.train[1].camera.intrinsics().fl_y, 20.0);  // fl_y defaults to the frame's fl_x
  EXPECT_EQ(d.train[2].camera.intrinsics().fl_x, 9.6);
  EXPECT_EQ(d.train[2].camera.intrinsics().cy, 2.5);
}

TEST(Dataset, FilePathWithoutExtensionResolves) {
  const fs::path dir = MakeTempDir(TestName());
  WriteTinyDataset(dir);
  EditJson(dir / "transforms_train.json",
           [](Json& d) { d["frames"][0]["file_path"] = "./images/train_000"; });
  const Dataset d = LoadDataset(dir).value();
  EXPECT_EQ(d.train[0].file_path, "./images/train_000.png");
  EXPECT_TRUE(fs::exists(d.ImagePath(d.train[0])));
}

TEST(Dataset, LoadsNerfaceLayoutDirectly) {
  const fs::path dir = MakeTempDir(TestName());
  const testing::TinyNerfaceInfo info = testing::WriteTinyNerfaceDataset(dir);
  const Result<Dataset> result = LoadDataset(dir);
  ASSERT_TRUE(result.ok()) << result.status().message();
  const Dataset& d = *result;
  EXPECT_EQ(d.train.size(), 3u);
  EXPECT_EQ(d.val.size(), 1u);
  EXPECT_EQ(d.test.size(), 1u);
  EXPECT_EQ(d.expression_dim, 76);
  EXPECT_EQ(d.train[2].expression.size(), 76u);
  EXPECT_EQ(d.train[0].file_path, "./train/f_0000.png");
  const Intrinsics& k = d.train[0].camera.intrinsics();
  EXPECT_EQ(k.width, 8);
  EXPECT_EQ(k.fl_x, info.intrinsics[0]);  // "intrinsics" wins over camera_angle_x
  EXPECT_EQ(k.fl_y, info.intrinsics[1]);
  EXPECT_DOUBLE_EQ(k.cx, 0.5 * 8 + 0.5);  // fraction of the width; NerFace rays use integer pixels
  EXPECT_DOUBLE_EQ(k.cy, 0.45 * 8 + 0.5);
  ASSERT_TRUE(d.background_file_path.has_value());
  EXPECT_EQ(*d.background_file_path, "bg/00050.png");
  EXPECT_LT((d.background - info.background_mean).cwiseAbs().maxCoeff(), 1e-6f);
  ASSERT_TRUE(d.train[1].bbox.has_value());
  EXPECT_EQ((*d.train[1].bbox)[2], 0.2f);
}

TEST(Dataset, NerfaceRaysMatchTheirConvention) {
  // NerFace: direction of integer pixel (i, j) = ((i - W cx) / fx, -(j - H cy) / fy, -1) in the camera frame.
  const fs::path dir = MakeTempDir(TestName());
  const testing::TinyNerfaceInfo info = testing::WriteTinyNerfaceDataset(dir);
  const Dataset d = LoadDataset(dir).value();
  const Camera& camera = d.train[1].camera;
  const int i = 5, j = 2;
  const Vec3d dir_cam((i - 8 * info.intrinsics[2]) / info.intrinsics[0],
                      -(j - 8 * info.intrinsics[3]) / info.intrinsics[1], -1.0);
  const Vec3d expected = (camera.world_from_cam().block<3, 3>(0, 0) * dir_cam).normalized();
  const Ray ray = camera.PixelRay(i, j);
  EXPECT_LT((ray.direction.cast<double>() - expected).norm(), 1e-6);
}

// Our camera of every frame of `split` against NerFace's reading of `file` (testing::NerfaceRay), at
// every pixel: the same world-frame ray (origin and normalised direction), and Project of a point on
// it gives back that pixel's centre.
void ExpectNerfaceRays(const std::vector<Frame>& frames, const fs::path& file) {
  const Json doc = ReadJsonFile(file).value();
  ASSERT_EQ(frames.size(), doc["frames"].size());
  for (size_t f = 0; f < frames.size(); ++f) {
    const Camera& camera = frames[f].camera;
    EXPECT_TRUE(ValidateRigid(camera.world_from_cam()).ok()) << camera.ToString();
    for (int j = 0; j < camera.height(); ++j) {
      for (int i = 0; i < camera.width(); ++i) {
        SCOPED_TRACE(file.filename().string() + " frame " + std::to_string(f) + " pixel (" +
                     std::to_string(i) + ", " + std::to_string(j) + ")");
        const testing::RayD expected =
            testing::NerfaceRay(doc, int(f), camera.width(), camera.height(), i, j);
        const Ray ray = camera.PixelRay(i, j);
        EXPECT_LT((ray.origin.cast<double>() - expected.origin).norm(), 1e-6);
        EXPECT_LT((ray.direction.cast<double>().normalized() - expected.direction).norm(), 1e-6);
        const auto projection = camera.Project(expected.origin + 2.5 * expected.direction);
        ASSERT_TRUE(projection.has_value());
        EXPECT_NEAR(projection->uv.x(), i + 0.5, 1e-9);
        EXPECT_NEAR(projection->uv.y(), j + 0.5, 1e-9);
        const Vec3d axis = camera.world_from_cam().block<3, 1>(0, 2);  // camera +Z: the view is along -Z
        EXPECT_NEAR(projection->depth, -2.5 * axis.dot(expected.direction), 1e-9);
      }
    }
  }
}

TEST(Dataset, NerfaceNegativeFocalLengthsCastNerfacesRays) {
  // real_to_nerf.py's fx, fy < 0 in the file; train frames 1 and 2 mirrored (one negative focal each).
  const fs::path dir = MakeTempDir(TestName());
  testing::TinyNerfaceOptions options;
  options.signed_focals = true;
  const testing::TinyNerfaceInfo info = testing::WriteTinyNerfaceDataset(dir, options);
  ASSERT_LT(info.intrinsics[0], 0);
  ASSERT_LT(info.intrinsics[1], 0);
  const Result<Dataset> result = LoadDataset(dir);
  ASSERT_TRUE(result.ok()) << result.status().message();
  const Dataset& d = *result;
  ExpectNerfaceRays(d.train, dir / "transforms_train.json");
  ExpectNerfaceRays(d.val, dir / "transforms_val.json");
  ExpectNerfaceRays(d.test, dir / "transforms_test.json");
  // Both negative: an ordinary camera turned 180 degrees about its axis, with positive focal lengths.
  const Intrinsics& k0 = d.train[0].camera.intrinsics();
  EXPECT_EQ(k0.fl_x, -info.intrinsics[0]);
  EXPECT_EQ(k0.fl_y, -info.intrinsics[1]);
  EXPECT_DOUBLE_EQ(k0.cx, 0.5 * 8 + 0.5);
  EXPECT_DOUBLE_EQ(k0.cy, 0.45 * 8 + 0.5);
  // One negative: a mirrored camera, which keeps fl_x < 0 (and fl_y > 0) with a rigid pose.
  for (int f : {1, 2}) {
    EXPECT_LT(d.train[f].camera.intrinsics().fl_x, 0) << f;
    EXPECT_GT(d.train[f].camera.intrinsics().fl_y, 0) << f;
  }
  // Our own format follows the same rule: saved and loaded back, the cameras are unchanged.
  ASSERT_TRUE(SaveDataset(d).ok());
  const Dataset again = LoadDataset(dir).value();
  ExpectSameFrames(d.train, again.train);
  ExpectSameFrames(d.test, again.test);
}

TEST(Dataset, ZeroOrNonFiniteFocalLengthIsAnError) {
  const fs::path dir = MakeTempDir(TestName());
  testing::WriteTinyNerfaceDataset(dir);
  EditJson(dir / "transforms_train.json", [](Json& d) { d["intrinsics"][0] = 0.0; });
  ExpectLoadError(dir,
                  "transforms_train.json: intrinsics: focal lengths [fx, fy] must be nonzero finite numbers");
  testing::WriteTinyNerfaceDataset(dir);
  EditJson(dir / "transforms_test.json", [](Json& d) {
    d["frames"][0]["intrinsics"] = {-10.0, 0.0, 0.5, 0.5};
  });
  ExpectLoadError(dir, "transforms_test.json: frames[0].intrinsics: focal lengths [fx, fy] must be nonzero");
  testing::WriteTinyNerfaceDataset(dir);
  EditJson(dir / "transforms_train.json", [](Json& d) { d["intrinsics"][1] = "@INF@"; });
  std::string text = ReadFile(dir / "transforms_train.json").value();
  text.replace(text.find("\"@INF@\""), 7, "-Infinity");
  ASSERT_TRUE(WriteFileAtomic(dir / "transforms_train.json", text).ok());
  ExpectLoadError(dir, "transforms_train.json: intrinsics: non-finite value -Infinity at [1]");

  const fs::path ours = MakeTempDir(TestName() + "_ours");
  WriteTinyDataset(ours);
  EditJson(ours / "transforms_train.json", [](Json& d) { d["frames"][1]["fl_y"] = 0.0; });
  ExpectLoadError(ours,
                  "transforms_train.json: frames[1].fl_y: focal length must be a nonzero finite number");
  WriteTinyDataset(ours);
  // Negative: accepted, a mirrored camera.
  EditJson(ours / "transforms_train.json", [](Json& d) { d["fl_x"] = -9.6; });
  const Result<Dataset> mirrored = LoadDataset(ours);
  ASSERT_TRUE(mirrored.ok()) << mirrored.status().message();
  EXPECT_EQ(mirrored->train[0].camera.intrinsics().fl_x, -9.6);
}

}  // namespace
}  // namespace icef
