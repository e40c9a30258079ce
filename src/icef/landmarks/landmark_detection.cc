#include "icef/landmarks/landmark_detection.h"

#include <algorithm>
#include <atomic>
#include <mutex>
#include <optional>
#include <set>
#include <sstream>

#include "icef/io/atomic_file.h"
#include "icef/io/json_util.h"
#include "icef/landmarks/face_mesh.h"

namespace icef {
namespace {

constexpr const char* kSplitNames[] = {"train", "test", "val"};

const std::vector<Frame>& SplitFrames(const Dataset& dataset, const std::string& split) {
  if (split == "train") return dataset.train;
  if (split == "test") return dataset.test;
  ICEF_CHECK(split == "val", "unknown split " + split);
  return dataset.val;
}

bool Selected(const LandmarkDetectionOptions& options, const std::string& split) {
  return std::find(options.splits.begin(), options.splits.end(), split) != options.splits.end();
}

}  // namespace

Status LandmarkDetectionOptions::Validate() const {
  if (splits.empty()) return Status::Error("splits: empty (give any of train, test, val)");
  std::set<std::string> seen;
  for (const std::string& s : splits) {
    if (s != "train" && s != "test" && s != "val")
      return Status::Error("splits: unknown split \"" + s + "\" (expected train, test or val)");
    if (!seen.insert(s).second) return Status::Error("splits: \"" + s + "\" given twice");
  }
  return Status::Ok();
}

std::string LandmarkDetectionOptions::ToString() const {
  std::string s = "LandmarkDetectionOptions(splits=";
  for (size_t i = 0; i < splits.size(); ++i) s += (i ? "," : "") + splits[i];
  return s + ", overwrite=" + (overwrite ? "true" : "false") + ", averaged=" + (averaged ? "true" : "false") +
         ", mesh=" + (mesh ? "true" : "false") + ", predictor=" +
         (predictor_path.empty() ? std::string(kDefaultShapePredictorPath) : predictor_path.string()) + ")";
}

const char* LandmarkOutcomeName(LandmarkOutcome outcome) {
  switch (outcome) {
    case LandmarkOutcome::kKept:
      return "kept";
    case LandmarkOutcome::kDetected:
      return "detected";
    case LandmarkOutcome::kNoFace:
      return "no face";
  }
  return "?";
}

std::string FrameLandmarks::Name() const { return split + "[" + std::to_string(index) + "] " + file_path; }

int LandmarkDetectionReport::Count(const std::string& split, LandmarkOutcome outcome) const {
  return int(std::count_if(frames.begin(), frames.end(), [&](const FrameLandmarks& f) {
    return f.split == split && f.outcome == outcome;
  }));
}

int LandmarkDetectionReport::CountAll(LandmarkOutcome outcome) const {
  return int(std::count_if(frames.begin(), frames.end(),
                           [&](const FrameLandmarks& f) { return f.outcome == outcome; }));
}

std::vector<const FrameLandmarks*> LandmarkDetectionReport::NoFace(const std::string& split) const {
  std::vector<const FrameLandmarks*> out;
  for (const FrameLandmarks& f : frames)
    if (f.outcome == LandmarkOutcome::kNoFace && (split.empty() || f.split == split)) out.push_back(&f);
  return out;
}

std::string LandmarkDetectionReport::Summary() const {
  std::ostringstream s;
  for (const char* split : kSplitNames) {
    const int total = int(std::count_if(frames.begin(), frames.end(),
                                        [&](const FrameLandmarks& f) { return f.split == split; }));
    if (total == 0) continue;
    s << split << ": " << total << " frame" << (total == 1 ? "" : "s") << ", "
      << Count(split, LandmarkOutcome::kDetected) << " detected, " << Count(split, LandmarkOutcome::kNoFace)
      << " without a face, " << Count(split, LandmarkOutcome::kKept) << " kept (already had landmarks)\n";
  }
  const std::vector<const FrameLandmarks*> missing = NoFace();
  if (missing.empty()) {
    s << "a face was found in every processed frame\n";
  } else {
    s << "no face found in " << missing.size() << " frame" << (missing.size() == 1 ? "" : "s") << ":\n";
    for (const FrameLandmarks* f : missing) s << "  " << f->Name() << "\n";
  }
  return s.str();
}

Result<Image> LoadDetectionImage(const Dataset& dataset, const Frame& frame, const Image& background_image) {
  ICEF_ASSIGN_OR_RETURN(const Image image, LoadFrameImage(dataset, frame));
  if (!image.HasAlpha()) return CompositeOver(image, dataset.background);  // RGB (grey expanded)
  if (background_image.empty() || background_image.width != image.width ||
      background_image.height != image.height)
    return CompositeOver(image, dataset.background);
  Image out(image.width, image.height, 3);
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x) {
      const float a = image.At(x, y, 3);
      const Vec3f c = a * image.Rgb(x, y) + (1.f - a) * background_image.Rgb(x, y);
      for (int k = 0; k < 3; ++k) out.At(x, y, k) = c[k];
    }
  return out;
}

Result<LandmarkDetectionReport> DetectDatasetLandmarks(
    const Dataset& dataset, const LandmarkDetectionOptions& options, const Executor& executor,
    const std::function<void(int64_t done, int64_t total)>& progress) {
  ICEF_RETURN_IF_ERROR(options.Validate());
  LandmarkDetectionReport report;
  std::vector<std::pair<size_t, const Frame*>> jobs;  // (report slot, frame)
  for (const char* split : kSplitNames) {
    if (!Selected(options, split)) continue;
    const std::vector<Frame>& frames = SplitFrames(dataset, split);
    for (size_t i = 0; i < frames.size(); ++i) {
      FrameLandmarks f;
      f.split = split;
      f.index = int(i);
      f.file_path = frames[i].file_path;
      const bool process = options.overwrite || !frames[i].landmarks_2d.has_value();
      if (process) jobs.emplace_back(report.frames.size(), &frames[i]);
      report.frames.push_back(std::move(f));
    }
  }
  if (jobs.empty()) return report;

  Image background_image;
  if (dataset.background_file_path) {
    ICEF_ASSIGN_OR_RETURN(background_image, ReadImage(dataset.root / *dataset.background_file_path));
  }
  ICEF_ASSIGN_OR_RETURN(const FaceLandmarkDetector detector,
                        FaceLandmarkDetector::Load(options.predictor_path));
  std::optional<FaceMesh> face_mesh;
  if (options.mesh) {
    ICEF_ASSIGN_OR_RETURN(FaceMesh loaded, FaceMesh::Load(options.mesh_dir));
    face_mesh = std::move(loaded);
  }
  const Executor workers(std::min<int>(executor.num_threads(), int(jobs.size())));
  std::vector<FaceLandmarkDetector> detectors;  // one per thread, cloned here (not concurrently)
  for (int t = 0; t < workers.num_threads(); ++t) detectors.push_back(detector.Clone());

  std::vector<Status> errors(jobs.size());
  std::mutex progress_mutex;
  int64_t done = 0;
  ParallelFor(workers, int64_t(jobs.size()), [&](int64_t begin, int64_t end, int thread) {
    for (int64_t j = begin; j < end; ++j) {
      const auto [slot, frame] = jobs[j];
      FrameLandmarks& out = report.frames[slot];
      Result<Image> image = LoadDetectionImage(dataset, *frame, background_image);
      if (!image.ok()) {
        errors[j] = image.status();
        continue;
      }
      Result<FaceDetection> face = face_mesh ? DetectFaceWithMesh(detectors[thread], *face_mesh, *image)
                                             : detectors[thread].DetectFace(*image, options.averaged);
      if (face.ok()) {
        out.outcome = LandmarkOutcome::kDetected;
        out.detection = std::move(face).value();
      } else {
        out.outcome = LandmarkOutcome::kNoFace;
      }
      if (progress) {
        std::lock_guard<std::mutex> lock(progress_mutex);
        progress(++done, int64_t(jobs.size()));
      }
    }
  });
  for (const Status& e : errors) ICEF_RETURN_IF_ERROR(e);  // the first failing frame by order
  return report;
}

Status WriteDetectedLandmarks(const Dataset& dataset, const LandmarkDetectionReport& report) {
  for (const char* split : kSplitNames) {
    std::vector<const FrameLandmarks*> detected;
    for (const FrameLandmarks& f : report.frames)
      if (f.split == split && f.outcome == LandmarkOutcome::kDetected) detected.push_back(&f);
    if (detected.empty()) continue;
    const std::filesystem::path file = dataset.root / ("transforms_" + std::string(split) + ".json");
    ICEF_ASSIGN_OR_RETURN(Json doc, ReadJsonFile(file));
    const size_t expected = SplitFrames(dataset, split).size();
    if (!doc.is_object() || !doc.contains("frames") || !doc["frames"].is_array() ||
        doc["frames"].size() != expected)
      return Status::Error(file.string() + ": frames: changed since the dataset was loaded (expected " +
                           std::to_string(expected) + " frames); nothing written to it");
    Json& frames = doc["frames"];
    for (const FrameLandmarks* f : detected) {
      ICEF_CHECK(f->index >= 0 && size_t(f->index) < expected, "frame index out of range");
      ICEF_CHECK(f->detection.landmarks.size() == size_t(kNumLandmarks), "detection without 68 landmarks");
      Json& frame = frames[size_t(f->index)];
      if (!frame.is_object())
        return Status::Error(file.string() + ": frames[" + std::to_string(f->index) + "]: not an object");
      Json points = Json::array();
      for (const Vec2f& p : f->detection.landmarks)
        points.push_back(Json::array({JsonFloat(p.x()), JsonFloat(p.y())}));
      frame["landmarks_2d"] = std::move(points);
      frame["landmarks_2d_visible"] = Json(std::vector<bool>(kNumLandmarks, true));
    }
    ICEF_RETURN_IF_ERROR(WriteFileAtomic(file, FormatJson(doc)));
  }
  return Status::Ok();
}

}  // namespace icef
