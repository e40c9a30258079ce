// `icef train`: load a dataset, resolve the run config (defaults < --config file < --set overrides
// < dedicated flags), train with a progress bar, write the model directory.
#pragma once

#include <filesystem>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "icef/core/status.h"
#include "icef/train/train_config.h"
#include "icef/train/trainer.h"

namespace icef {

struct TrainAppOptions {
  std::filesystem::path dataset;                     // dataset directory
  std::filesystem::path out;                         // model directory
  std::optional<std::string> method;                 // overrides model.method
  std::optional<int64_t> steps;                      // overrides train.steps
  std::optional<double> time_budget;                 // overrides train.time_budget_seconds
  std::optional<std::filesystem::path> config_file;  // run config JSON
  std::optional<int64_t> seed;                       // overrides train.seed
  std::optional<int> threads;                        // overrides train.threads
  std::vector<std::string> overrides;                // "section.key=value"
  bool resume = false;                               // continue from out/checkpoint.icef
  bool overwrite = false;  // allow training into a directory that already holds a model
  bool quiet = false;      // no progress bar
};

// Resolves the run config the options describe (without training).
Result<RunConfig> ResolveRunConfig(const TrainAppOptions& options);

// The keys a resumed run may change: the step count, time budget, thread count and what to do on
// a non-finite step.
const std::vector<std::string>& ResumableConfigKeys();

// The config of a resumed run: the checkpoint's config `saved`, then (as for a fresh run) --config
// (a whole run config: defaults < file), --set and the flags. A result that differs from `saved`
// in any key but ResumableConfigKeys() is refused with an error naming `checkpoint` and each key
// with both values.
Result<RunConfig> ResolveResumeConfig(const TrainAppOptions& options, const RunConfig& saved,
                                      const std::string& checkpoint);

Result<TrainSummary> RunTrain(const TrainAppOptions& options, std::ostream& out);

}  // namespace icef
