// icef import SRC --out DST [--format auto|nerface|instant-ngp|icef] [--link]: converts a dataset
// into our format.
#include <iostream>
#include <memory>
#include <string>

#include "icef/cli/commands.h"
#include "icef/data/dataset_import.h"

namespace icef::cli {

CommandFn RegisterImport(CLI::App& app) {
  struct Args {
    std::string src;
    std::string out;
    std::string format = "auto";
    bool link = false;
  };
  auto args = std::make_shared<Args>();
  app.description(
      "Convert a NerFace or instant-ngp dataset into ICEF's format: images copied to OUT/images, "
      "transforms_*.json rewritten with explicit intrinsics, expression_dim and background. "
      "OUT must not exist (or be empty); the source is never modified.");
  app.add_option("src", args->src, "Source dataset directory (holding transforms_train.json)")->required();
  app.add_option("--out,-o", args->out, "Destination directory (created)")->required();
  app.add_option("--format", args->format, "Source layout: auto, nerface, instant-ngp or icef")
      ->check(CLI::IsMember({"auto", "nerface", "instant-ngp", "icef"}));
  app.add_flag("--link", args->link, "Hard-link images instead of copying them");
  return [args]() -> Status {
    ImportOptions options;
    options.format = *ParseDatasetFormat(args->format);
    options.link_images = args->link;
    ICEF_ASSIGN_OR_RETURN(const ImportReport report, ImportDataset(args->src, args->out, options));
    std::cout << report.ToString() << "\n";
    return Status::Ok();
  };
}

}  // namespace icef::cli
