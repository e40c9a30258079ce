#include <iostream>

#include "icef/cli/commands.h"

namespace icef::cli {

CommandFn RegisterDemo(CLI::App& app) {
  app.description("Run the built-in demo: today it lists what the tool can do.");
  return []() -> Status {
    std::cout << "icef demo: the synthetic-subject pipeline is not built yet; see README.\n";
    return Status::Ok();
  };
}

}  // namespace icef::cli
