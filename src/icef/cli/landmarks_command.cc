// icef landmarks DATASET [--splits train,test,val] [--overwrite] [--threads N] [--predictor FILE]
// Detects the 68 iBUG landmarks of the dataset's frames with dlib's HOG face detector and 68-point
// shape predictor (the largest face of each image composited over the dataset's background) and
// writes them into transforms_<split>.json as landmarks_2d + landmarks_2d_visible (all true).
// Frames that already have landmarks_2d are left alone unless --overwrite.
//
// Each file is replaced atomically and keeps every other key. The landmarks that were found are
// saved even when some frame has no face, so a rerun only processes the frames still missing.
// Exit 0 when a face was found in every processed training frame (frames of test/val without a
// face are listed as warnings), otherwise exit 1 with an error naming the training frames.
#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "icef/cli/commands.h"
#include "icef/core/parallel.h"
#include "icef/core/progress.h"
#include "icef/data/dataset.h"
#include "icef/landmarks/landmark_detection.h"

namespace icef::cli {
namespace {

struct LandmarksArgs {
  std::string dataset;
  std::vector<std::string> splits = {"train", "test", "val"};
  bool overwrite = false;
  int threads = 0;
  std::string predictor;
};

Status RunLandmarks(const LandmarksArgs& args) {
  LandmarkDetectionOptions options;
  options.splits = args.splits;
  options.overwrite = args.overwrite;
  options.predictor_path = args.predictor;
  if (Status valid = options.Validate(); !valid.ok()) return valid.WithContext("--splits");
  ICEF_ASSIGN_OR_RETURN(const Dataset dataset, LoadDataset(args.dataset));

  std::optional<ProgressBar> bar;
  auto progress = [&](int64_t done, int64_t total) {
    if (!bar) bar.emplace("landmarks", total, std::cout, StdoutIsTerminal());
    bar->Update(done);
  };
  ICEF_ASSIGN_OR_RETURN(const LandmarkDetectionReport report,
                        DetectDatasetLandmarks(dataset, options, Executor(args.threads), progress));
  if (bar) bar->Finish();
  ICEF_RETURN_IF_ERROR(WriteDetectedLandmarks(dataset, report));
  // What was written must load back (it always should: a failure here is reported, not hidden).
  if (const int written = report.CountAll(LandmarkOutcome::kDetected); written > 0) {
    const Result<Dataset> reloaded = LoadDataset(args.dataset);
    if (!reloaded.ok()) return reloaded.status().WithContext("the dataset does not load after writing landmarks");
  }
  std::cout << report.Summary();
  const int detected = report.CountAll(LandmarkOutcome::kDetected);
  std::cout << "wrote landmarks of " << detected << " frame" << (detected == 1 ? "" : "s") << " into "
            << args.dataset << "\n";

  const std::vector<const FrameLandmarks*> missing = report.NoFace("train");
  if (missing.empty()) return Status::Ok();
  std::string names;
  for (const FrameLandmarks* f : missing) names += (names.empty() ? "" : ", ") + f->Name();
  return Status::Error("no face found in " + std::to_string(missing.size()) + " training frame" +
                       (missing.size() == 1 ? "" : "s") + ": " + names +
                       " (the other frames' landmarks were saved; give these frames landmarks_2d by hand or "
                       "replace their images, then rerun: only frames without landmarks are processed)");
}

}  // namespace

CommandFn RegisterLandmarks(CLI::App& app) {
  auto args = std::make_shared<LandmarksArgs>();
  app.add_option("dataset", args->dataset, "Dataset directory (holding transforms_train.json)")->required();
  app.add_option("--splits", args->splits, "Comma-separated splits to process (default train,test,val)")
      ->delimiter(',');
  app.add_flag("--overwrite", args->overwrite, "Re-detect frames that already have landmarks_2d");
  app.add_option("--threads", args->threads, "Worker threads, one detector each (0 = all cores)");
  app.add_option("--predictor", args->predictor,
                 "dlib 68-point shape predictor (default " + std::string(kDefaultShapePredictorPath) + ")");
  return [args]() { return RunLandmarks(*args); };
}

}  // namespace icef::cli
