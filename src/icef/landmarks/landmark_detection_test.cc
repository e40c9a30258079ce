#include "icef/landmarks/landmark_detection.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "icef/io/atomic_file.h"
#include "icef/io/json_util.h"
#include "icef/synth/synthesize.h"
#include "icef/testing/tiny_dataset.h"

namespace icef {
namespace {

namespace fs = std::filesystem;

bool HavePredictor() { return fs::exists(kDefaultShapePredictorPath); }

// A small synthetic-head dataset (K = 2, 160x160, one test view) whose ground-truth landmarks
// are kept aside and removed from the returned dataset.
struct SynthFixture {
  Dataset dataset;
  std::vector<std::vector<Vec2f>> truth;         // per training frame
  std::vector<std::vector<bool>> truth_visible;  // per training frame
};

SynthFixture MakeSynthFixture(const std::string& name) {
  synth::SynthOptions options;
  options.out_dir = testing::MakeTempDir(name);
  options.num_train = 2;
  options.resolution = 160;
  options.test_views = 1;
  options.novel_per_tier = 0;
  SynthFixture f;
  const Status status = synth::SynthesizeDataset(options, Executor(2), nullptr, &f.dataset);
  EXPECT_TRUE(status.ok()) << status.ToString();
  for (Frame& frame : f.dataset.train) {
    f.truth.push_back(frame.landmarks_2d.value());
    f.truth_visible.push_back(frame.landmarks_2d_visible.value());
  }
  for (auto* frames : {&f.dataset.train, &f.dataset.test}) {
    for (Frame& frame : *frames) {
      frame.landmarks_2d.reset();
      frame.landmarks_2d_visible.reset();
    }
  }
  return f;
}

TEST(LandmarkDetectionOptions, Validate) {
  LandmarkDetectionOptions options;
  EXPECT_TRUE(options.Validate().ok());
  options.splits = {"train", "tset"};
  EXPECT_NE(options.Validate().message().find("tset"), std::string::npos);
  options.splits = {"train", "train"};
  EXPECT_NE(options.Validate().message().find("twice"), std::string::npos);
  options.splits = {};
  EXPECT_FALSE(options.Validate().ok());
  EXPECT_NE(LandmarkDetectionOptions().ToString().find("splits=train,test,val"), std::string::npos);
}

// dlib finds the synthetic head and its landmarks lie near the generator's ground truth; the
// result does not depend on the thread count.
TEST(DetectDatasetLandmarks, FindsSyntheticHeadNearGroundTruth) {
  if (!HavePredictor()) GTEST_SKIP() << "libdlib-data not installed";
  const SynthFixture f = MakeSynthFixture("landmarks_synth");
  LandmarkDetectionOptions options;
  int64_t last_done = 0, last_total = 0;
  Result<LandmarkDetectionReport> report =
      DetectDatasetLandmarks(f.dataset, options, Executor(2), [&](int64_t done, int64_t total) {
        EXPECT_EQ(done, last_done + 1);
        last_done = done;
        last_total = total;
      });
  ASSERT_TRUE(report.ok()) << report.status().ToString();
  const int num_frames = int(f.dataset.train.size() + f.dataset.test.size());
  ASSERT_EQ(int(report->frames.size()), num_frames);
  EXPECT_EQ(last_done, num_frames);
  EXPECT_EQ(last_total, num_frames);
  EXPECT_EQ(report->CountAll(LandmarkOutcome::kDetected), num_frames) << report->Summary();
  for (size_t k = 0; k < f.dataset.train.size(); ++k) {
    const FrameLandmarks& frame = report->frames[k];
    ASSERT_EQ(frame.split, "train");
    ASSERT_EQ(frame.detection.landmarks.size(), size_t(kNumLandmarks));
    double sum = 0;
    int n = 0;
    for (int i = 0; i < kNumLandmarks; ++i) {
      if (!f.truth_visible[k][i]) continue;
      sum += (frame.detection.landmarks[i] - f.truth[k][i]).norm();
      ++n;
    }
    const double face_width = frame.detection.box_max.x() - frame.detection.box_min.x();
    // A different model of the same 68 points: a few pixels apart, never a different face part.
    EXPECT_LT(sum / n, 0.08 * face_width) << "train[" << k << "] mean error " << sum / n << " px";
  }
  const Result<LandmarkDetectionReport> serial = DetectDatasetLandmarks(f.dataset, options, Executor(1));
  ASSERT_TRUE(serial.ok());
  for (size_t i = 0; i < report->frames.size(); ++i)
    EXPECT_EQ(serial->frames[i].detection.landmarks, report->frames[i].detection.landmarks) << i;
}

TEST(DetectDatasetLandmarks, KeepsExistingLandmarksUnlessOverwriting) {
  const fs::path dir = testing::MakeTempDir("landmarks_keep");
  testing::TinyDatasetOptions tiny;
  tiny.landmarks_2d = true;
  const Dataset dataset = testing::WriteTinyDataset(dir, tiny);
  LandmarkDetectionOptions options;
  options.predictor_path = dir / "no_predictor_needed.dat";  // nothing to detect: never loaded
  Result<LandmarkDetectionReport> report = DetectDatasetLandmarks(dataset, options, Executor(2));
  ASSERT_TRUE(report.ok()) << report.status().ToString();
  EXPECT_EQ(report->CountAll(LandmarkOutcome::kKept), 5);
  options.overwrite = true;
  report = DetectDatasetLandmarks(dataset, options, Executor(2));
  ASSERT_FALSE(report.ok());
  EXPECT_NE(report.status().message().find("no_predictor_needed.dat"), std::string::npos);
}

// Tiny 8x6 gradients hold no face: every frame is reported, and a split can be left out.
TEST(DetectDatasetLandmarks, ReportsFramesWithoutFace) {
  if (!HavePredictor()) GTEST_SKIP() << "libdlib-data not installed";
  const fs::path dir = testing::MakeTempDir("landmarks_noface");
  testing::TinyDatasetOptions tiny;
  tiny.landmarks_2d = false;
  tiny.num_val = 1;
  const Dataset dataset = testing::WriteTinyDataset(dir, tiny);
  LandmarkDetectionOptions options;
  options.splits = {"train", "val"};
  const Result<LandmarkDetectionReport> report = DetectDatasetLandmarks(dataset, options, Executor(2));
  ASSERT_TRUE(report.ok()) << report.status().ToString();
  EXPECT_EQ(report->frames.size(), 4u);
  EXPECT_EQ(report->Count("train", LandmarkOutcome::kNoFace), 3);
  EXPECT_EQ(report->Count("val", LandmarkOutcome::kNoFace), 1);
  EXPECT_EQ(report->NoFace("train").size(), 3u);
  const std::string summary = report->Summary();
  EXPECT_NE(summary.find("train: 3 frames, 0 detected, 3 without a face"), std::string::npos) << summary;
  EXPECT_NE(summary.find("val[0] images/val_000.png"), std::string::npos) << summary;
  EXPECT_EQ(summary.find("test"), std::string::npos) << summary;
}

// A report as the detector would return it, with recognisable landmarks on the given frames.
LandmarkDetectionReport FakeReport(const std::string& split, const std::vector<int>& detected,
                                   int num_frames) {
  LandmarkDetectionReport report;
  for (int i = 0; i < num_frames; ++i) {
    FrameLandmarks f;
    f.split = split;
    f.index = i;
    f.outcome = LandmarkOutcome::kNoFace;
    if (std::find(detected.begin(), detected.end(), i) != detected.end()) {
      f.outcome = LandmarkOutcome::kDetected;
      for (int p = 0; p < kNumLandmarks; ++p)
        f.detection.landmarks.emplace_back(0.25f * p + i, 0.5f * p + 0.125f);
    }
    report.frames.push_back(f);
  }
  return report;
}

TEST(WriteDetectedLandmarks, WritesDetectedFramesAndKeepsEverythingElse) {
  const fs::path dir = testing::MakeTempDir("landmarks_write");
  testing::TinyDatasetOptions tiny;
  tiny.landmarks_2d = false;
  Dataset dataset = testing::WriteTinyDataset(dir, tiny);
  // Keys of another tool must survive.
  Json doc = ReadJsonFile(dir / "transforms_train.json").value();
  doc["other_tool"] = {{"version", 3}};
  doc["frames"][1]["other_tool_frame_key"] = "keep me";
  ASSERT_TRUE(WriteFileAtomic(dir / "transforms_train.json", FormatJson(doc)).ok());
  const std::string test_before = ReadFile(dir / "transforms_test.json").value();

  ASSERT_TRUE(WriteDetectedLandmarks(dataset, FakeReport("train", {0, 2}, 3)).ok());
  const Json written = ReadJsonFile(dir / "transforms_train.json").value();
  EXPECT_EQ(written["other_tool"]["version"], 3);
  EXPECT_EQ(written["frames"][1]["other_tool_frame_key"], "keep me");
  EXPECT_FALSE(written["frames"][1].contains("landmarks_2d"));
  EXPECT_EQ(ReadFile(dir / "transforms_test.json").value(), test_before);  // no detections: untouched

  const Result<Dataset> loaded = LoadDataset(dir);
  ASSERT_TRUE(loaded.ok()) << loaded.status().ToString();
  for (int i : {0, 2}) {
    const Frame& frame = loaded->train[i];
    ASSERT_TRUE(frame.landmarks_2d.has_value());
    ASSERT_TRUE(frame.landmarks_2d_visible.has_value());
    for (int p = 0; p < kNumLandmarks; ++p) {
      EXPECT_EQ((*frame.landmarks_2d)[p], Vec2f(0.25f * p + i, 0.5f * p + 0.125f));
      EXPECT_TRUE((*frame.landmarks_2d_visible)[p]);
    }
  }
  EXPECT_FALSE(loaded->train[1].landmarks_2d.has_value());
}

TEST(WriteDetectedLandmarks, RefusesAFileThatChanged) {
  const fs::path dir = testing::MakeTempDir("landmarks_changed");
  testing::TinyDatasetOptions tiny;
  tiny.landmarks_2d = false;
  const Dataset dataset = testing::WriteTinyDataset(dir, tiny);
  Json doc = ReadJsonFile(dir / "transforms_train.json").value();
  doc["frames"].erase(doc["frames"].size() - 1);
  const std::string changed = FormatJson(doc);
  ASSERT_TRUE(WriteFileAtomic(dir / "transforms_train.json", changed).ok());
  const Status status = WriteDetectedLandmarks(dataset, FakeReport("train", {0}, 3));
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("transforms_train.json: frames: changed"), std::string::npos)
      << status.message();
  EXPECT_EQ(ReadFile(dir / "transforms_train.json").value(), changed);
}

// A NerFace dataset keeps its own layout (camera_angle_x, intrinsics, paths without extension).
TEST(WriteDetectedLandmarks, KeepsNerfaceLayout) {
  const fs::path dir = testing::MakeTempDir("landmarks_nerface");
  testing::WriteTinyNerfaceDataset(dir);
  const Dataset dataset = LoadDataset(dir).value();
  ASSERT_TRUE(WriteDetectedLandmarks(dataset, FakeReport("val", {0}, 1)).ok());
  const Json written = ReadJsonFile(dir / "transforms_val.json").value();
  EXPECT_TRUE(written.contains("camera_angle_x"));
  EXPECT_TRUE(written.contains("intrinsics"));
  EXPECT_FALSE(written.contains("w"));
  const std::string path = written["frames"][0]["file_path"];
  EXPECT_FALSE(fs::path(path).has_extension()) << path;
  const Dataset reloaded = LoadDataset(dir).value();
  EXPECT_TRUE(reloaded.val[0].landmarks_2d.has_value());
}

}  // namespace
}  // namespace icef
