// `icef import SRC --out DST [--format auto|nerface|instant-ngp|icef] [--link]`: converts a NerFace
// or instant-ngp dataset into our format (data/dataset_import.h) and prints the report.
#pragma once

#include <filesystem>
#include <ostream>
#include <string>

#include "icef/core/status.h"

namespace icef {

struct ImportAppOptions {
  std::filesystem::path src;    // source dataset directory (holding transforms_train.json)
  std::filesystem::path out;    // destination directory (created; must not exist, or be empty)
  std::string format = "auto";  // source layout: auto, nerface, instant-ngp or icef
  bool link = false;            // hard-link images instead of copying them
};

// Imports src into out and prints the report on `out_stream`; errors name the file or option.
Status RunImport(const ImportAppOptions& options, std::ostream& out_stream);

}  // namespace icef
