// icef bench --out DIR [--identities N] [--k 3,5,10] [--methods a,b] [--res R] [--steps S |
//   --time-budget T] [--quick] [--validation] [--shard i/n] [--threads N] [--set section.key=value ...]
// icef bench merge DIR... --out DIR   (or icef bench --merge DIR... --out DIR)
// icef bench --real SOURCE... --out DIR [--k 3,5,10] [--methods a,b] [--test N] [--video-frames N] [--res R]
// app/bench_app.h.
#include <filesystem>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "icef/app/bench_app.h"
#include "icef/app/real_bench_app.h"
#include "icef/cli/commands.h"
#include "icef/core/progress.h"

namespace icef::cli {

namespace {

// What the options bind to. `given` holds the options that win over --quick / --validation (and
// over the real bench's defaults) only when given; its defaults are the ones --help shows.
struct BenchArgs {
  BenchAppOptions app;
  eval::BenchOptions given;
  std::vector<std::string> merge;
  std::vector<std::string> merge_inputs;
  std::string merge_out;
  int real_test = RealBenchOptions().test_frames;
  int video_frames = RealBenchOptions().video_frames;
  std::string face_model = RealBenchOptions().face_model;
};

// --out ... --time-budget: what is run and for how long.
void AddRunOptions(CLI::App& app, BenchArgs& args) {
  eval::BenchOptions& o = args.given;
  app.add_option("--out,-o", args.app.out, "Output directory (created)");
  app.add_option("--identities", o.identities,
                 "Number of identities (test seeds 1..N; with --validation 6, seeds 101..106)")
      ->capture_default_str();
  app.add_option("--first-seed", o.first_identity_seed, "Seed of the first identity")->capture_default_str();
  app.add_option("--k", args.app.ks, "Training-frame counts K, comma-separated (default 3,5,10)");
  app.add_option("--methods", args.app.methods,
                 "Methods (default: all seven: icef-prior, warp-prior, icef, icef-no-conf, icef-uniform, "
                 "warp, nerface)")
      ->delimiter(',');
  app.add_option(
         "--replicates", o.replicates,
         "Train every (identity, K, method) this many times with different training seeds (identity seed, "
         "then + 1000 per replicate); the report averages them per identity and gives their spread")
      ->capture_default_str();
  app.add_option("--res", o.resolution, "Image width = height")->capture_default_str();
  app.add_option("--test-views", o.test_views, "Held-out test views per dataset")->capture_default_str();
  app.add_option("--novel-per-tier", o.novel_per_tier, "Novel test expressions per tier")
      ->capture_default_str();
  app.add_option("--steps", o.steps, "Training steps per run (same for every run; alone: no time cap)")
      ->capture_default_str();
  app.add_option("--time-budget", o.time_budget_seconds,
                 "Training wall-clock cap per run, seconds (0 = none)")
      ->capture_default_str();
}

// --config ... --keep-models: the runs' config, the suites and the scorers.
void AddSetupOptions(CLI::App& app, BenchArgs& args) {
  eval::BenchOptions& o = args.given;
  app.add_option("--config", o.config_path, "Base run config file (default: built-in defaults)");
  app.add_option("--set", o.overrides,
                 "Config override for every run, e.g. train.batch_rays=2048 (repeatable)");
  app.add_flag("--quick", args.app.quick,
               "Tiny settings for CI: 1 identity, K=3, 32x32, 20 steps of a tiny model");
  app.add_flag(
      "--validation", args.app.validation,
      "Validation bench: validation identities (seeds 101 and up, 6 by default) at K=5 in diverse scenes "
      "(skin, lighting, head placement, camera, view spread, resolution 128-256 and fine detail drawn per "
      "identity, as `icef synth --diverse`; --res pins the resolution), methods icef and icef-prior, icef "
      "train's default steps (2000) with no time cap (reproducible), for tuning and prior experiments. "
      "Without it the identities are test seeds (below 101) in the classic scene, which are only reported, "
      "never tuned on");
  app.add_option("--shard", args.app.shard,
                 "Run only shard i of n (i/n, 0-based): runs i, i+n, ... of the stable order");
  app.add_option("--threads", o.threads, "Worker threads (0 = all cores)")->capture_default_str();
  app.add_option("--faceid-model", o.faceid_model_dir, "Face-identity model directory");
  app.add_option("--lpips-weights", o.lpips_weights, "LPIPS weights file (without it LPIPS is null)");
  app.add_flag("--keep-models", o.keep_models, "Keep each run's trained model under runs/<name>/model/");
}

// --real, --test, --video-frames: the bench on real media.
void AddRealOptions(CLI::App& app, BenchArgs& args) {
  app.add_option(
         "--real", args.app.real,
         "Real media instead of synthetic identities: videos, photo folders or datasets from icef track. "
         "Each is tracked once; for each K the avatar trains on the K frames that cover pose and expression "
         "best and renders every held-out frame at its tracked camera and expression, scored against the "
         "real photo (face and head PSNR/SSIM, LPIPS, identity distance, real_expr_gain, tracking residual). "
         "Defaults: methods icef-prior,icef, 256 px, 1000 steps")
      ->expected(1, -1);
  app.add_option("--test", args.real_test, "With --real: held-out frames per source")->capture_default_str();
  app.add_option("--video-frames", args.video_frames, "With --real: frames tracked per video, spread over it")
      ->capture_default_str();
  app.add_option(
         "--face-model", args.face_model,
         "The face model the datasets are expressed in and the prior stands on: procedural or ict "
         "(ICT-FaceKit). With --real: the sources are tracked with it (icef track --face-model); "
         "synthetic: each synthesised dataset is re-expressed in it with its cameras held (icef track "
         "--keep-cameras --face-model ict --landmarks model), a model-mismatch test")
      ->check(CLI::IsMember({"procedural", "ict"}))
      ->capture_default_str();
}

// --merge and `icef bench merge`; returns the subcommand.
CLI::App* AddMerge(CLI::App& app, BenchArgs& args) {
  app.add_option("--merge", args.merge, "Merge these bench directories into --out instead of running");
  CLI::App* merge = app.add_subcommand("merge",
                                       "Build one report from several bench directories (shards, or parts of "
                                       "the same bench over other identity seeds, methods or Ks)");
  merge->add_option("dirs", args.merge_inputs, "Bench directories")->required();
  merge->add_option("--out,-o", args.merge_out, "Output directory")->required();
  return merge;
}

// The app's options: the bound ones, with those of `given` that were given on the command line.
BenchAppOptions ToAppOptions(const BenchArgs& args, const CLI::App& app, const CLI::App& merge) {
  BenchAppOptions options = args.app;
  const eval::BenchOptions& given = args.given;
  options.base = given;
  if (app.count("--identities")) options.identities = given.identities;
  if (app.count("--first-seed")) options.first_seed = given.first_identity_seed;
  if (app.count("--res")) options.resolution = given.resolution;
  if (app.count("--test-views")) options.test_views = given.test_views;
  if (app.count("--novel-per-tier")) options.novel_per_tier = given.novel_per_tier;
  if (app.count("--steps")) options.steps = given.steps;
  if (app.count("--time-budget")) options.time_budget = given.time_budget_seconds;
  if (app.count("--test")) options.real_test_frames = args.real_test;
  if (app.count("--video-frames")) options.video_frames = args.video_frames;
  if (app.count("--face-model")) options.real_face_model = args.face_model;
  for (const std::string& d : merge.parsed() ? args.merge_inputs : args.merge) options.merge.emplace_back(d);
  if (merge.parsed()) options.out = args.merge_out;
  options.interactive = StdoutIsTerminal();
  return options;
}

}  // namespace

CommandFn RegisterBench(CLI::App& app) {
  auto args = std::make_shared<BenchArgs>();
  app.description(
      "Run the benchmark: for each identity seed x K x method, synthesise a dataset (cached in DIR/data/), "
      "train with the same budget, evaluate, and write DIR/runs/<id>_k<K>_<method>/metrics.json; then "
      "DIR/report.md, report.json, report.tex (the tables in LaTeX, booktabs) and plots/. Re-running skips "
      "finished runs. `icef bench merge A B --out C` builds one report from shard directories.");
  AddRunOptions(app, *args);
  AddSetupOptions(app, *args);
  AddRealOptions(app, *args);
  CLI::App* merge = AddMerge(app, *args);
  CLI::App* self = &app;
  return [args, merge, self]() { return RunBench(ToAppOptions(*args, *self, *merge), std::cout); };
}

}  // namespace icef::cli
