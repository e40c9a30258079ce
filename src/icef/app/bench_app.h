// `icef bench --out DIR ...`: the whole evaluation protocol (study/bench_protocol.h): synthesise,
// train and evaluate every identity x K x method, then report.md, report.json, report.tex and plots. This
// resolves the command's options into eval::BenchOptions: the defaults, then --validation, then
// --quick, with the options given explicitly winning over both.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "icef/app/real_bench_app.h"
#include "icef/core/status.h"
#include "icef/study/bench_protocol.h"

namespace icef {

struct BenchAppOptions {
  eval::BenchOptions base;    // config, overrides, threads, faceid / LPIPS, keep_models (the rest is below)
  std::filesystem::path out;  // output directory
  std::optional<int> identities;       // number of identities (wins over --quick / --validation)
  std::optional<uint64_t> first_seed;  // seed of the first identity (wins over --validation)
  std::optional<int> resolution;       // image width = height (wins over --quick)
  std::optional<int> test_views;       // held-out test views per dataset (wins over --quick)
  std::optional<int> novel_per_tier;   // novel test expressions per tier (wins over --quick)
  std::optional<int64_t> steps;        // training steps per run; alone, it drops the time cap
  std::optional<double> time_budget;   // training wall-clock cap per run, seconds (0 = none)
  std::string ks;                      // training-frame counts, comma-separated (empty: the default)
  std::vector<std::string> methods;    // methods (empty: the default, all seven)
  std::string shard;                   // "i/n": run only shard i of n (empty: all runs)
  bool quick = false;                  // tiny settings for CI (eval::BenchOptions::ApplyQuick)
  bool validation = false;             // validation identities (eval::BenchOptions::ApplyValidation)
  bool interactive = false;            // redraw progress bars in place (stdout is a terminal)
  // Real media instead of synthetic identities (app/real_bench_app.h): videos, photo folders or
  // datasets from icef track; the options above that apply carry over (ResolveRealBenchOptions).
  std::vector<std::filesystem::path> real;
  std::optional<int> real_test_frames;         // with real: held-out frames per source
  std::optional<int> video_frames;             // with real: frames tracked per video, spread over it
  std::optional<std::string> real_face_model;  // with real: the tracker's face model (procedural or ict)
  // Bench directories to merge into `out` (one report) instead of running (eval::MergeBench).
  std::vector<std::filesystem::path> merge;

  // The resolved options' check (eval::BenchOptions::Validate); errors name the option.
  Status Validate() const;
};

// The bench the options describe (validated by eval::RunBench).
Result<eval::BenchOptions> ResolveBenchOptions(const BenchAppOptions& options);

// The real-media bench the options describe: RealBenchOptions' defaults (then --quick), with the
// options given explicitly winning.
Result<RealBenchOptions> ResolveRealBenchOptions(const BenchAppOptions& options);

// `icef bench`: merges the `merge` directories into `out`, runs the real-media bench (`real`) or
// resolves and runs the synthetic bench, logging on `out`.
Status RunBench(const BenchAppOptions& options, std::ostream& out);

}  // namespace icef
