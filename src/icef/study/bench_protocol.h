// The whole benchmark of docs/design.md §6 (`icef bench`): for each identity seed x K x method,
// synthesise the dataset (once per identity x K, cached in OUT/data/), train with the same budget,
// evaluate (eval/evaluate.h) and write OUT/runs/<id>_k<K>_<method>/metrics.json; then aggregate
// into OUT/report.md + report.json + plots (study/report.h). Resumable: a run whose metrics.json
// exists is skipped. Runs are ordered stably (identity, K, method); --shard i/n takes runs i,
// i + n, i + 2n, ... so several machines can share a bench, and MergeBench builds one report from
// their output directories.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <ostream>
#include <string>
#include <vector>

#include "icef/core/status.h"
#include "icef/io/json_util.h"
#include "icef/study/report.h"

namespace icef::eval {

// Default training budget of every bench run (the same for every method): this many steps, but
// no more than kDefaultBenchTimeBudget seconds of training, so that the default bench (45 runs at
// 128x128) fits in about 90 minutes on a 2-core machine. The report gives the steps each run made.
constexpr int64_t kDefaultBenchSteps = 1000;
constexpr double kDefaultBenchTimeBudget = 90.0;

// Identity seeds are split once and for all: seeds below kFirstValidationSeed are test identities
// (what the bench reports; never used to choose a default or a hyperparameter), seeds from
// kFirstValidationSeed on are validation identities (`icef bench --validation`: what tuning and
// prior experiments use).
constexpr uint64_t kFirstValidationSeed = 101;
constexpr int kDefaultValidationIdentities = 6;
// The largest resolution a diverse bench draws (evaluation cost grows with the pixels).
constexpr int kMaxValidationResolution = 256;

struct BenchOptions {
  // Output directory (created): data/, runs/, plots/, report.md, report.json, bench.json.
  std::filesystem::path out_dir;
  // Number of identities N; their seeds are first_identity_seed .. first_identity_seed + N - 1.
  int identities = 3;
  // Seed of the first identity.
  uint64_t first_identity_seed = 1;
  // Training-frame counts K.
  std::vector<int> ks = {3, 5, 10};
  // Methods (names of model/method.h).
  // (icef-no-id is left out: it trains the same model as warp, see model/method.h.)
  std::vector<std::string> methods = {"icef-prior",   "warp-prior", "icef",   "icef-no-conf",
                                      "icef-uniform", "warp",       "nerface"};
  // Image width = height in pixels.
  int resolution = 128;
  // Held-out test views per dataset.
  int test_views = 3;
  // Novel test expressions per tier (near, moderate, far).
  int novel_per_tier = 2;
  // Trainings per (identity, K, method), each with its own training seed (RunId::TrainSeed): the
  // report averages them per identity and gives their spread (two trainings of one identity can
  // differ by more than a prior changes, docs/results/priors_validation.md).
  int replicates = 1;
  // Training steps per run (the same budget for every run).
  int64_t steps = kDefaultBenchSteps;
  // Wall-clock budget per run in seconds (0 = none; with it, steps is only an upper bound).
  double time_budget_seconds = kDefaultBenchTimeBudget;
  // Base run config file ("" = built-in defaults); method, steps, budget, seed and threads are set per run.
  std::string config_path;
  // "section.key=value" overrides applied to every run's config (RunConfig::ApplyOverride).
  std::vector<std::string> overrides;
  // Shard i of n (0 <= i < n): runs i, i + n, ... of the stable run order.
  int shard_index = 0;
  int shard_count = 1;
  // Worker threads (0 = all cores).
  int threads = 0;
  // Face-identity model directory ("" = default lookup) and LPIPS weights file ("" = unavailable).
  std::string faceid_model_dir;
  std::string lpips_weights;
  // Keep each run's trained model (runs/<name>/model/); by default it is deleted after evaluation.
  bool keep_models = false;
  // Validation bench: the identities are validation seeds (>= kFirstValidationSeed); otherwise
  // they must all be test seeds (< kFirstValidationSeed).
  bool validation = false;
  // Diverse scenes (`icef synth --diverse`): every scene axis of synth::SceneAxes drawn per
  // identity seed (the validation bench's default); draw_resolution: the resolution is drawn too
  // (up to kMaxValidationResolution) instead of `resolution`.
  bool diverse = false;
  bool draw_resolution = false;
  // The face model the datasets are expressed in: "procedural" (as synthesised) or "ict": each
  // synthesised dataset is re-expressed by `reexpress` (set by the app: icef track --keep-cameras
  // --face-model ict --landmarks model) into data/<name>_ict/ and the runs train and score on it,
  // against the procedural renders: a model-mismatch test.
  std::string face_model = "procedural";
  std::function<Result<Dataset>(const Dataset& source, const std::filesystem::path& out_dir)> reexpress;

  // The --validation settings: validation seeds 101..106, K = 5, diverse scenes with a drawn
  // resolution, methods icef and icef-prior, `icef train`'s default steps with no time cap (a pure
  // step budget; explicit options win).
  void ApplyValidation();
  // "test: ..." or "validation: ..." for the report.
  std::string IdentityRole() const;

  // The --quick settings: 1 identity, K = 3, all methods, 32x32, 1 test view, 1 novel expression
  // per tier, 20 steps on a tiny model (seconds in all, for CI).
  void ApplyQuick();
  Status Validate() const;
  std::string ToString() const;
  Json ToJson() const;  // what report.md / bench.json show (no paths)
};

// The --quick bench's tiny model, as "section.key=value" overrides (seconds a run, for CI).
std::vector<std::string> TinyModelOverrides();

// Parses "i/n" (0 <= i < n).
Status ParseShard(const std::string& text, int* index, int* count);
// Parses "3,5,10".
Result<std::vector<int>> ParseIntList(const std::string& text, const std::string& what);

// Every run in the stable order: identity-major, then K, then method as given.
std::vector<RunId> PlanRuns(const BenchOptions& options);
// Runs index, index + count, index + 2 count, ... of `runs`.
std::vector<RunId> ShardRuns(const std::vector<RunId>& runs, int index, int count);

// Runs the bench (progress and a summary go to `log`; bars redraw in place when interactive) and
// writes the report of every run finished in out_dir so far.
Status RunBench(const BenchOptions& options, std::ostream& log, bool interactive);

// Builds one report in out_dir from the runs/ of several bench (shard) directories: each run's
// metrics.json is copied to out_dir/runs/<name>/; of a run present in several inputs the first is
// kept (with a warning on `log` when their metrics differ). Renders stay in the inputs; a validation
// bench's worst identities' training-view sheets are drawn from there. Inputs with different bench
// settings (bench.json, shard aside) are an error.
Status MergeBench(const std::vector<std::filesystem::path>& inputs, const std::filesystem::path& out_dir,
                  std::ostream& log);

}  // namespace icef::eval
