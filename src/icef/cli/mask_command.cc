// icef mask DATASET --out DIR [--frame I] [--threads N]: app/mask_app.h.
#include <iostream>
#include <memory>

#include "icef/app/mask_app.h"
#include "icef/cli/commands.h"

namespace icef::cli {

CommandFn RegisterMask(CLI::App& app) {
  auto o = std::make_shared<MaskAppOptions>();
  auto threads = std::make_shared<int>(0);
  app.add_option("dataset", o->dataset, "Dataset directory (holding transforms_train.json)")->required();
  app.add_option("--out", o->out, "Output directory for the PNGs (created if missing)")->required();
  app.add_option("--frame", o->frame, "Training frame to overlay the mask on (default 0)");
  app.add_option("--threads", *threads, "Worker threads (0 = all cores)");
  return [o, threads]() { return RunMask(*o, Executor(*threads), std::cout); };
}

}  // namespace icef::cli
