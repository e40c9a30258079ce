// icef bench --out DIR [--identities N] [--k 3,5,10] [--methods a,b] [--res R] [--steps S |
//   --time-budget T] [--quick] [--validation] [--shard i/n] [--threads N] [--set section.key=value ...]
// icef bench merge DIR... --out DIR   (or icef bench --merge DIR... --out DIR)
// icef bench --real SOURCE... --out DIR [--k 3,5,10] [--methods a,b] [--test N] [--video-frames N] [--res R]
// app/bench_app.h (merge: eval::MergeBench).
#include <filesystem>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "icef/app/bench_app.h"
#include "icef/app/real_bench_app.h"
#include "icef/cli/commands.h"
#include "icef/core/progress.h"
#include "icef/eval/bench_protocol.h"

namespace icef::cli {

CommandFn RegisterBench(CLI::App& app) {
  struct Args {
    BenchAppOptions app;
    eval::BenchOptions options;  // bound to the options that win over --quick / --validation when given
    std::vector<std::string> merge;
    std::vector<std::string> merge_inputs;
    std::string merge_out;
    std::vector<std::filesystem::path> real;
    int real_test = RealBenchOptions().test_frames;
    int video_frames = RealBenchOptions().video_frames;
  };
  auto args = std::make_shared<Args>();
  eval::BenchOptions& o = args->options;
  app.description(
      "Run the benchmark: for each identity seed x K x method, synthesise a dataset (cached in DIR/data/), train "
      "with the same budget, evaluate, and write DIR/runs/<id>_k<K>_<method>/metrics.json; then DIR/report.md, "
      "report.json, report.tex (the tables in LaTeX, booktabs) and plots/. Re-running skips finished runs. "
      "`icef bench merge A B --out C` builds one report from shard directories.");
  app.add_option("--out,-o", args->app.out, "Output directory (created)");
  app.add_option("--identities", o.identities, "Number of identities (test seeds 1..N; with --validation 6, seeds 101..106)")
      ->capture_default_str();
  app.add_option("--first-seed", o.first_identity_seed, "Seed of the first identity")->capture_default_str();
  app.add_option("--k", args->app.ks, "Training-frame counts K, comma-separated (default 3,5,10)");
  app.add_option("--methods", args->app.methods, "Methods (default: all seven: icef-prior, warp-prior, icef, icef-no-conf, icef-uniform, warp, nerface)")->delimiter(',');
  app.add_option("--replicates", o.replicates,
                 "Train every (identity, K, method) this many times with different training seeds (identity seed, "
                 "then + 1000 per replicate); the report averages them per identity and gives their spread")
      ->capture_default_str();
  app.add_option("--res", o.resolution, "Image width = height")->capture_default_str();
  app.add_option("--test-views", o.test_views, "Held-out test views per dataset")->capture_default_str();
  app.add_option("--novel-per-tier", o.novel_per_tier, "Novel test expressions per tier")->capture_default_str();
  app.add_option("--steps", o.steps, "Training steps per run (same for every run; alone: no time cap)")->capture_default_str();
  app.add_option("--time-budget", o.time_budget_seconds, "Training wall-clock cap per run, seconds (0 = none)")
      ->capture_default_str();
  app.add_option("--config", o.config_path, "Base run config file (default: built-in defaults)");
  app.add_option("--set", o.overrides, "Config override for every run, e.g. train.batch_rays=2048 (repeatable)");
  app.add_flag("--quick", args->app.quick, "Tiny settings for CI: 1 identity, K=3, 32x32, 20 steps of a tiny model");
  app.add_flag("--validation", args->app.validation,
               "Validation bench: validation identities (seeds 101 and up, 6 by default) at K=5 in diverse scenes "
               "(skin, lighting, head placement, camera, view spread, resolution 128-256 and fine detail drawn per "
               "identity, as `icef synth --diverse`; --res pins the resolution), methods icef and icef-prior, "
               "icef train's default steps (2000) with no time cap (reproducible), for tuning and prior experiments. Without it the identities are test seeds (below 101) in the classic "
               "scene, which are only reported, never tuned on");
  app.add_option("--shard", args->app.shard, "Run only shard i of n (i/n, 0-based): runs i, i+n, ... of the stable order");
  app.add_option("--threads", o.threads, "Worker threads (0 = all cores)")->capture_default_str();
  app.add_option("--faceid-model", o.faceid_model_dir, "Face-identity model directory");
  app.add_option("--lpips-weights", o.lpips_weights, "LPIPS weights file (without it LPIPS is null)");
  app.add_flag("--keep-models", o.keep_models, "Keep each run's trained model under runs/<name>/model/");
  app.add_option("--real", args->real,
                 "Real media instead of synthetic identities: videos, photo folders or datasets from icef track. Each "
                 "is tracked once; for each K the avatar trains on the K frames that cover pose and expression best "
                 "and renders every held-out frame at its tracked camera and expression, scored against the real "
                 "photo (face and head PSNR/SSIM, LPIPS, identity distance, real_expr_gain, tracking residual). "
                 "Defaults: methods icef-prior,icef, 256 px, 1000 steps")
      ->expected(1, -1);
  app.add_option("--test", args->real_test, "With --real: held-out frames per source")->capture_default_str();
  app.add_option("--video-frames", args->video_frames, "With --real: frames tracked per video, spread over it")
      ->capture_default_str();
  app.add_option("--merge", args->merge, "Merge these bench directories into --out instead of running");
  CLI::App* merge = app.add_subcommand("merge", "Build one report from several bench directories (shards, or parts of the same bench over other identity seeds, methods or Ks)");
  merge->add_option("dirs", args->merge_inputs, "Bench directories")->required();
  merge->add_option("--out,-o", args->merge_out, "Output directory")->required();
  CLI::App* self = &app;
  return [args, merge, self]() -> Status {
    const bool interactive = StdoutIsTerminal();
    if (merge->parsed() || !args->merge.empty()) {
      std::vector<std::filesystem::path> inputs;
      for (const auto& d : merge->parsed() ? args->merge_inputs : args->merge) inputs.emplace_back(d);
      const std::string out = merge->parsed() ? args->merge_out : args->app.out.string();
      if (out.empty()) return Status::Error("bench merge: --out is required");
      return eval::MergeBench(inputs, out, std::cout);
    }
    const eval::BenchOptions& given = args->options;
    if (!args->real.empty()) {
      RealBenchOptions r;
      r.sources = args->real;
      r.out_dir = args->app.out;
      if (args->app.quick) r.ApplyQuick();
      if (!args->app.ks.empty()) {
        ICEF_ASSIGN_OR_RETURN(r.ks, eval::ParseIntList(args->app.ks, "--k"));
      }
      if (!args->app.methods.empty()) r.methods = args->app.methods;
      if (self->count("--test")) r.test_frames = args->real_test;
      if (self->count("--video-frames")) r.video_frames = args->video_frames;
      if (self->count("--res")) r.resolution = given.resolution;
      if (self->count("--steps")) r.steps = given.steps;
      if (self->count("--time-budget")) r.time_budget_seconds = given.time_budget_seconds;
      r.config_path = given.config_path;
      r.overrides.insert(r.overrides.end(), given.overrides.begin(), given.overrides.end());
      r.threads = given.threads;
      r.faceid_model_dir = given.faceid_model_dir;
      r.lpips_weights = given.lpips_weights;
      r.keep_models = given.keep_models;
      r.interactive = interactive;
      return RunRealBench(r, std::cout);
    }
    if (self->count("--test") || self->count("--video-frames"))
      return Status::Error("--test and --video-frames go with --real (synthetic benches: --test-views)");
    BenchAppOptions options = args->app;
    options.base = given;
    if (self->count("--identities")) options.identities = given.identities;
    if (self->count("--first-seed")) options.first_seed = given.first_identity_seed;
    if (self->count("--res")) options.resolution = given.resolution;
    if (self->count("--test-views")) options.test_views = given.test_views;
    if (self->count("--novel-per-tier")) options.novel_per_tier = given.novel_per_tier;
    if (self->count("--steps")) options.steps = given.steps;
    if (self->count("--time-budget")) options.time_budget = given.time_budget_seconds;
    options.interactive = interactive;
    return RunBench(options, std::cout);
  };
}

}  // namespace icef::cli
