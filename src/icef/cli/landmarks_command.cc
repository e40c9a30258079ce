// icef landmarks DATASET [--splits train,test,val] [--overwrite] [--threads N] [--predictor FILE]:
// app/landmarks_app.h. Exit 1 when a training frame has no face.
#include <iostream>
#include <memory>

#include "icef/app/landmarks_app.h"
#include "icef/cli/commands.h"
#include "icef/core/progress.h"

namespace icef::cli {

CommandFn RegisterLandmarks(CLI::App& app) {
  auto o = std::make_shared<LandmarksAppOptions>();
  auto threads = std::make_shared<int>(0);
  app.add_option("dataset", o->dataset, "Dataset directory (holding transforms_train.json)")->required();
  app.add_option("--splits", o->splits, "Comma-separated splits to process (default train,test,val)")
      ->delimiter(',');
  app.add_flag("--overwrite", o->overwrite, "Re-detect frames that already have landmarks_2d");
  app.add_option("--threads", *threads, "Worker threads, one detector each (0 = all cores)");
  app.add_option("--predictor", o->predictor,
                 "dlib 68-point shape predictor (default " + DefaultShapePredictorPath() + ")");
  return [o, threads]() {
    LandmarksAppOptions options = *o;
    options.interactive = StdoutIsTerminal();
    return RunLandmarks(options, Executor(*threads), std::cout);
  };
}

}  // namespace icef::cli
