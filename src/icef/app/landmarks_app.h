// `icef landmarks DATASET [--splits train,test,val] [--overwrite] [--predictor FILE]`: detects the
// 68 iBUG landmarks of the dataset's frames with dlib's HOG face detector and 68-point shape
// predictor (the largest face of each image composited over the dataset's background) and writes
// them into transforms_<split>.json as landmarks_2d + landmarks_2d_visible (all true). Frames that
// already have landmarks_2d are left alone unless overwrite.
//
// Each file is replaced atomically and keeps every other key. The landmarks that were found are
// saved even when some frame has no face, so a rerun only processes the frames still missing.
// Succeeds when a face was found in every processed training frame (frames of test/val without a
// face are listed as warnings), otherwise fails with an error naming the training frames.
#pragma once

#include <filesystem>
#include <ostream>
#include <string>
#include <vector>

#include "icef/core/parallel.h"
#include "icef/core/status.h"

namespace icef {

struct LandmarksAppOptions {
  std::filesystem::path dataset;  // dataset directory (holding transforms_train.json)
  std::vector<std::string> splits = {"train", "test", "val"};  // splits to process
  bool overwrite = false;           // re-detect frames that already have landmarks_2d
  std::filesystem::path predictor;  // dlib 68-point shape predictor (empty: the default)
  bool interactive = false;         // redraw the progress bar in place (stdout is a terminal)

  // Errors name the option (--splits ...).
  Status Validate() const;
};

// dlib's 68-point shape predictor used when none is given (also by `icef track`).
std::string DefaultShapePredictorPath();

// Detects, writes the landmarks back and prints the report on `out` (the executor's threads run
// one detector each).
Status RunLandmarks(const LandmarksAppOptions& options, const Executor& executor, std::ostream& out);

}  // namespace icef
