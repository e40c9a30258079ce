// icef sheet DATASET... --out FILE.png [--tile N --columns N]: a labelled contact sheet of a dataset's
// training frames, neutral test views and one test frame per expression and tier; of several
// datasets, one row of training frames each.
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "icef/cli/commands.h"
#include "icef/synth/contact_sheet.h"

namespace icef::cli {

CommandFn RegisterSheet(CLI::App& app) {
  struct Args {
    std::vector<std::string> datasets;
    std::string out;
    synth::ContactSheetOptions options;
  };
  auto args = std::make_shared<Args>();
  app.description(
      "Tile a dataset's training frames, neutral test views and test frames per tier into one PNG. With several "
      "datasets: one row of training frames per dataset (e.g. the subjects of `icef synth --diverse` side by side).");
  app.add_option("dataset", args->datasets, "Dataset directories (holding transforms_train.json)")->required();
  app.add_option("--out,-o", args->out, "Output PNG")->required();
  app.add_option("--tile", args->options.tile, "Tile size in pixels")->capture_default_str();
  app.add_option("--columns", args->options.max_columns, "Most tiles per row")->capture_default_str();
  return [args]() -> Status {
    std::vector<Dataset> datasets;
    for (const std::string& d : args->datasets) {
      ICEF_ASSIGN_OR_RETURN(Dataset dataset, LoadDataset(d));
      datasets.push_back(std::move(dataset));
    }
    ICEF_ASSIGN_OR_RETURN(const Image sheet, datasets.size() == 1 ? synth::MakeContactSheet(datasets[0], args->options)
                                                                  : synth::MakeTrainingSheet(datasets, args->options));
    ICEF_RETURN_IF_ERROR(WritePng(args->out, sheet));
    std::cout << "wrote " << args->out << " (" << sheet.width << "x" << sheet.height << ")\n";
    return Status::Ok();
  };
}

}  // namespace icef::cli
