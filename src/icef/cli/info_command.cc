// icef info DATASET [--json]: app/info_app.h.
#include <iostream>
#include <memory>

#include "icef/app/info_app.h"
#include "icef/cli/commands.h"

namespace icef::cli {

CommandFn RegisterInfo(CLI::App& app) {
  auto o = std::make_shared<InfoAppOptions>();
  app.description(
      "Validate a dataset (ours, instant-ngp or NerFace layout) and print a summary: frames per split, "
      "resolution, intrinsics, aabb, expressions, landmarks, tiers, expression-distance ranges. Reads only; "
      "a malformed dataset gives one error line and exit code 1. Images: the header and the file structure "
      "are checked (a truncated or bit-flipped PNG, a truncated JPEG is refused), the pixels are not decoded "
      "(for speed); damage inside compressed data shows when `icef train` reads the images.");
  app.add_option("dataset", o->dataset, "Dataset directory (holding transforms_train.json)")->required();
  app.add_flag("--json", o->json, "Print the summary as JSON instead of text");
  return [o]() { return RunInfo(*o, std::cout); };
}

}  // namespace icef::cli
