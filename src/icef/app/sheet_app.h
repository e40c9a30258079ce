// `icef sheet DATASET... --out FILE.png [--tile N --columns N]`: a labelled contact sheet of a
// dataset's training frames, neutral test views and one test frame per expression and tier; of
// several datasets, one row of training frames each (synth/contact_sheet.h).
#pragma once

#include <filesystem>
#include <ostream>
#include <string>
#include <vector>

#include "icef/core/status.h"
#include "icef/synth/contact_sheet.h"

namespace icef {

struct SheetAppOptions {
  std::vector<std::string> datasets;  // dataset directories (holding transforms_train.json)
  std::filesystem::path out;          // output PNG
  synth::ContactSheetOptions sheet;   // tile size and most tiles per row
};

// Loads the datasets, writes the sheet and prints its path and size on `out`.
Status RunSheet(const SheetAppOptions& options, std::ostream& out);

}  // namespace icef
