#include <iostream>
#include <memory>
#include <string>

#include "icef/cli/commands.h"
#include "icef/data/dataset.h"

namespace icef::cli {

CommandFn RegisterInfo(CLI::App& app) {
  auto dir = std::make_shared<std::string>();
  app.add_option("dataset", *dir, "Dataset directory (holding transforms_train.json)")->required();
  return [dir]() -> Status {
    ICEF_ASSIGN_OR_RETURN(const Dataset dataset, LoadDataset(*dir));
    std::cout << dataset.ToString() << "\n";
    return Status::Ok();
  };
}

}  // namespace icef::cli
