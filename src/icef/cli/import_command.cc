// icef import SRC --out DST [--format auto|nerface|instant-ngp|icef] [--link]: app/import_app.h.
#include <iostream>
#include <memory>

#include "icef/app/import_app.h"
#include "icef/cli/commands.h"

namespace icef::cli {

CommandFn RegisterImport(CLI::App& app) {
  auto o = std::make_shared<ImportAppOptions>();
  app.description(
      "Convert a NerFace or instant-ngp dataset into ICEF's format: images copied to OUT/images, "
      "transforms_*.json rewritten with explicit intrinsics, expression_dim and background. OUT must not "
      "exist (or be empty); the source is never modified.");
  app.add_option("src", o->src, "Source dataset directory (holding transforms_train.json)")->required();
  app.add_option("--out,-o", o->out, "Destination directory (created)")->required();
  app.add_option("--format", o->format, "Source layout: auto, nerface, instant-ngp or icef")
      ->check(CLI::IsMember({"auto", "nerface", "instant-ngp", "icef"}));
  app.add_flag("--link", o->link, "Hard-link images instead of copying them");
  return [o]() { return RunImport(*o, std::cout); };
}

}  // namespace icef::cli
