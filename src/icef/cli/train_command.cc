#include <iostream>
#include <memory>

#include "icef/app/train_app.h"
#include "icef/cli/commands.h"
#include "icef/cli/validators.h"

namespace icef::cli {

CommandFn RegisterTrain(CLI::App& app) {
  app.description(
      "Train a model on a dataset. The run config is the defaults (docs/config.md), then --config FILE, then "
      "--set overrides, then the dedicated flags. Writes MODEL/checkpoint.icef (periodically, atomically), "
      "config.json, train_log.jsonl and summary.json. Ctrl-C stops after the current step with a checkpoint; "
      "--resume continues it with the checkpoint's run config: --config, --set and the flags may then change "
      "only "
      "train.steps, train.time_budget_seconds, train.threads and train.on_nonfinite (anything else is "
      "refused, "
      "naming the keys).");
  auto o = std::make_shared<TrainAppOptions>();
  auto method = std::make_shared<std::string>();
  auto steps = std::make_shared<int64_t>(0);
  auto budget = std::make_shared<double>(-1);
  auto config = std::make_shared<std::string>();
  auto seed = std::make_shared<int64_t>(-1);
  auto threads = std::make_shared<int>(-1);
  app.add_option("dataset", o->dataset, "Dataset directory (transforms_train.json ...)")->required();
  app.add_option("--out", o->out, "Model directory to write")->required();
  app.add_option("--method", *method,
                 "icef-prior | warp-prior | icef | icef-no-id | icef-no-conf | icef-uniform | warp | nerface "
                 "(default icef-prior: ICEF on the face model fitted to the training landmarks, "
                 "docs/face_model.md; it needs the face model's expression names: re-express other datasets "
                 "with icef track DATASET --keep-cameras, or train them with --method icef)");
  const TrainConfig defaults;
  app.add_option("--steps", *steps,
                 "Optimiser steps (train.steps, default " + std::to_string(defaults.steps) +
                     "; the bench and the demo train 1000)")
      ->check(kPositive);
  app.add_option("--time-budget", *budget,
                 "Stop after this many seconds of training, the step count still bounding it "
                 "(train.time_budget_seconds, "
                 "default 0 = no limit)")
      ->check(kNonNegative);
  app.add_option("--config", *config, "Run config JSON ({\"parent\", \"model\": {...}, \"train\": {...}})");
  app.add_option("--seed", *seed,
                 "Root random seed (train.seed, default " + std::to_string(defaults.seed) + ")")
      ->check(kNonNegative);
  app.add_option("--threads", *threads, "Worker threads (0 = all cores)")->check(kNonNegative);
  app.add_option("--set", o->overrides,
                 "Config override SECTION.KEY=VALUE, e.g. train.lambda_id=0.2 (repeatable)");
  app.add_flag(
      "--resume", o->resume,
      "Continue from MODEL/checkpoint.icef (its run config; only the step count, time budget, threads and "
      "train.on_nonfinite may change)");
  app.add_flag("--overwrite", o->overwrite, "Start afresh even if MODEL already holds a model");
  app.add_flag("--quiet", o->quiet, "No progress bar");
  return [=]() -> Status {
    TrainAppOptions opts = *o;
    if (!method->empty()) opts.method = *method;
    if (*steps > 0) opts.steps = *steps;
    if (*budget >= 0) opts.time_budget = *budget;
    if (!config->empty()) opts.config_file = *config;
    if (*seed >= 0) opts.seed = *seed;
    if (*threads >= 0) opts.threads = *threads;
    return RunTrain(opts, std::cout).status();
  };
}

}  // namespace icef::cli
