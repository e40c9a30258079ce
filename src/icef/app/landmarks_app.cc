#include "icef/app/landmarks_app.h"

#include <optional>

#include "icef/core/progress.h"
#include "icef/data/dataset.h"
#include "icef/landmarks/landmark_detection.h"

namespace icef {

namespace {
LandmarkDetectionOptions DetectionOptions(const LandmarksAppOptions& o) {
  LandmarkDetectionOptions options;
  options.splits = o.splits;
  options.overwrite = o.overwrite;
  options.predictor_path = o.predictor;
  return options;
}
}  // namespace

Status LandmarksAppOptions::Validate() const {
  if (dataset.empty()) return Status::Error("a dataset directory is required");
  return DetectionOptions(*this).Validate().WithContext("--splits");
}

std::string DefaultShapePredictorPath() { return kDefaultShapePredictorPath; }

Status RunLandmarks(const LandmarksAppOptions& o, const Executor& executor, std::ostream& out) {
  ICEF_RETURN_IF_ERROR(o.Validate());
  const LandmarkDetectionOptions options = DetectionOptions(o);
  ICEF_ASSIGN_OR_RETURN(const Dataset dataset, LoadDataset(o.dataset));

  std::optional<ProgressBar> bar;
  auto progress = [&](int64_t done, int64_t total) {
    if (!bar) bar.emplace("landmarks", total, out, o.interactive);
    bar->Update(done);
  };
  ICEF_ASSIGN_OR_RETURN(const LandmarkDetectionReport report,
                        DetectDatasetLandmarks(dataset, options, executor, progress));
  if (bar) bar->Finish();
  ICEF_RETURN_IF_ERROR(WriteDetectedLandmarks(dataset, report));
  // What was written must load back (it always should: a failure here is reported, not hidden).
  if (const int written = report.CountAll(LandmarkOutcome::kDetected); written > 0) {
    const Result<Dataset> reloaded = LoadDataset(o.dataset);
    if (!reloaded.ok())
      return reloaded.status().WithContext("the dataset does not load after writing landmarks");
  }
  out << report.Summary();
  const int detected = report.CountAll(LandmarkOutcome::kDetected);
  out << "wrote landmarks of " << detected << " frame" << (detected == 1 ? "" : "s") << " into "
      << o.dataset.string() << "\n";

  const std::vector<const FrameLandmarks*> missing = report.NoFace("train");
  if (missing.empty()) return Status::Ok();
  std::string names;
  for (const FrameLandmarks* f : missing) names += (names.empty() ? "" : ", ") + f->Name();
  return Status::Error("no face found in " + std::to_string(missing.size()) + " training frame" +
                       (missing.size() == 1 ? "" : "s") + ": " + names +
                       " (the other frames' landmarks were saved; give these frames landmarks_2d by hand or "
                       "replace their images, then rerun: only frames without landmarks are processed)");
}

}  // namespace icef
