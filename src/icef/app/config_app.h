// `icef config [FILE] [--set SECTION.KEY=VALUE ...] [--markdown]`: prints the resolved run config
// (the defaults, or FILE with its parents, then the overrides) as JSON, or with markdown the table
// of every key, its default and meaning (docs/config.md, train/train_config.h).
#pragma once

#include <filesystem>
#include <ostream>
#include <string>
#include <vector>

#include "icef/core/status.h"

namespace icef {

struct ConfigAppOptions {
  std::filesystem::path file;          // run config JSON to resolve (empty: the defaults)
  std::vector<std::string> overrides;  // "section.key=value", applied in order
  bool markdown = false;               // print the documentation table instead
};

// Prints the resolved config (or the documentation) on `out`; errors name the file and key.
Status PrintConfig(const ConfigAppOptions& options, std::ostream& out);

}  // namespace icef
