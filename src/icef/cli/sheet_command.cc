// icef sheet DATASET... --out FILE.png [--tile N --columns N]: app/sheet_app.h.
#include <iostream>
#include <memory>

#include "icef/app/sheet_app.h"
#include "icef/cli/commands.h"

namespace icef::cli {

CommandFn RegisterSheet(CLI::App& app) {
  auto o = std::make_shared<SheetAppOptions>();
  app.description(
      "Tile a dataset's training frames, neutral test views and test frames per tier into one PNG. With "
      "several datasets: one row of training frames per dataset (e.g. the subjects of `icef synth --diverse` "
      "side by side).");
  app.add_option("dataset", o->datasets, "Dataset directories (holding transforms_train.json)")->required();
  app.add_option("--out,-o", o->out, "Output PNG")->required();
  app.add_option("--tile", o->sheet.tile, "Tile size in pixels")->capture_default_str();
  app.add_option("--columns", o->sheet.max_columns, "Most tiles per row")->capture_default_str();
  return [o]() { return RunSheet(*o, std::cout); };
}

}  // namespace icef::cli
