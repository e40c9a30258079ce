// `icef info DATASET [--json]`: validates a dataset (ours, instant-ngp or NerFace layout) and prints
// its summary (data/dataset_summary.h) as text or JSON. Reads only.
#pragma once

#include <filesystem>
#include <ostream>

#include "icef/core/status.h"

namespace icef {

struct InfoAppOptions {
  std::filesystem::path dataset;  // dataset directory (holding transforms_train.json)
  bool json = false;              // print the summary as JSON instead of text
};

// Loads and validates the dataset (a dataset needs at least one training frame) and prints the
// summary on `out`; errors name the file and field.
Status RunInfo(const InfoAppOptions& options, std::ostream& out);

}  // namespace icef
