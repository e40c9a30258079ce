// icef config [FILE] [--set SECTION.KEY=VALUE ...] [--markdown]: app/config_app.h.
#include <iostream>
#include <memory>

#include "icef/app/config_app.h"
#include "icef/cli/commands.h"

namespace icef::cli {

CommandFn RegisterConfig(CLI::App& app) {
  app.description(
      "Print the resolved run config (defaults, or FILE with its parents and --set overrides applied) as "
      "JSON, or with --markdown the table of every key, its default and meaning (docs/config.md).");
  auto o = std::make_shared<ConfigAppOptions>();
  app.add_option("file", o->file, "Run config JSON to resolve (optional)");
  app.add_option("--set", o->overrides, "Override SECTION.KEY=VALUE (repeatable)");
  app.add_flag("--markdown", o->markdown, "Print the documentation table instead");
  return [o]() { return PrintConfig(*o, std::cout); };
}

}  // namespace icef::cli
