// `icef import`: converts an instant-ngp or NerFace dataset directory into our format
// (docs/design.md §4), copying or hard-linking its images.
#pragma once

#include <filesystem>
#include <optional>
#include <string>

#include "icef/core/status.h"
#include "icef/data/dataset.h"

namespace icef {

enum class DatasetFormat { kAuto, kIcef, kNerface, kInstantNgp };
const char* DatasetFormatName(DatasetFormat format);  // "auto", "icef", "nerface", "instant-ngp"
std::optional<DatasetFormat> ParseDatasetFormat(const std::string& name);

// Guesses a directory's layout from transforms_train.json: "expression_dim" means ours; a
// file-level or per-frame "intrinsics", per-frame "bbox", or a bg/ directory means NerFace;
// anything else is instant-ngp / NeRF-synthetic. Errors name the file.
Result<DatasetFormat> DetectDatasetFormat(const std::filesystem::path& dir);

struct ImportOptions {
  DatasetFormat format = DatasetFormat::kAuto;  // source layout; kAuto detects it
  bool link_images = false;  // hard-link images instead of copying (copies across filesystems)
  Status Validate() const;
  std::string ToString() const;
};

struct ImportReport {
  DatasetFormat format = DatasetFormat::kAuto;  // the source layout, detected or as given
  Dataset dataset;                              // as written (root = destination)
  int images = 0;                               // image files copied or linked
  std::string ToString() const;
};

// Loads and validates `src` (LoadDataset: our format, instant-ngp or NerFace), checks what the
// named format requires (NerFace: per-frame expressions), and writes it to `dst` in our format:
// images/<split>_NNNN<ext> (neutral images <split>_NNNN_neutral<ext>), a background image as
// background<ext> (background_file_path, with its mean colour as `background`) and the
// transforms files. `dst` must not exist or be an empty directory. Everything is written to a
// temporary sibling directory that is renamed into place at the end: on any error `dst` is left
// as it was and `src` is never modified.
Result<ImportReport> ImportDataset(const std::filesystem::path& src, const std::filesystem::path& dst,
                                   const ImportOptions& options);

}  // namespace icef
