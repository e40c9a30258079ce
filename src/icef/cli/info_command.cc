// icef info DATASET [--json]: validates a dataset and prints its summary.
#include <iostream>
#include <memory>
#include <string>

#include "icef/cli/commands.h"
#include "icef/core/parallel.h"
#include "icef/data/dataset.h"
#include "icef/data/dataset_summary.h"

namespace icef::cli {

CommandFn RegisterInfo(CLI::App& app) {
  struct Args {
    std::string dir;
    bool json = false;
  };
  auto args = std::make_shared<Args>();
  app.description(
      "Validate a dataset (ours, instant-ngp or NerFace layout) and print a summary: frames per split, "
      "resolution, intrinsics, aabb, expressions, landmarks, tiers, expression-distance ranges. "
      "Reads only; a malformed dataset gives one error line and exit code 1. Images: the header and the file "
      "structure are checked (a truncated or bit-flipped PNG, a truncated JPEG is refused), the pixels are not "
      "decoded (for speed); damage inside compressed data shows when `icef train` reads the images.");
  app.add_option("dataset", args->dir, "Dataset directory (holding transforms_train.json)")->required();
  app.add_flag("--json", args->json, "Print the summary as JSON instead of text");
  return [args]() -> Status {
    ICEF_ASSIGN_OR_RETURN(const Dataset dataset, LoadDataset(args->dir));
    if (dataset.train.empty())
      return Status::Error((dataset.root / "transforms_train.json").string() +
                           ": frames: the train split has no frames (a dataset needs at least one training frame)");
    const DatasetSummary summary = SummarizeDataset(dataset, Executor());
    std::cout << (args->json ? FormatJson(summary.ToJson()) : summary.ToString());
    return Status::Ok();
  };
}

}  // namespace icef::cli
