#include "icef/study/bench_protocol.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <map>
#include <memory>
#include <optional>
#include <sstream>

#include "icef/core/parallel.h"
#include "icef/core/progress.h"
#include "icef/eval/evaluate.h"
#include "icef/io/atomic_file.h"
#include "icef/model/method.h"
#include "icef/synth/synthesize.h"
#include "icef/train/train_config.h"
#include "icef/train/trainer.h"

namespace fs = std::filesystem;

namespace icef::eval {

std::vector<std::string> TinyModelOverrides() {
  return {"model.static_field.grid.num_levels=6",
          "model.static_field.grid.log2_table_size=12",
          "model.static_field.grid.finest_resolution=64",
          "model.static_field.density_hidden=32",
          "model.static_field.color_hidden=[32]",
          "model.deformation.hidden=[32, 32]",
          "model.sampler.num_samples=24",
          "model.occupancy.resolution=32",
          "train.batch_rays=512",
          "train.depth_prior_view_rays=64",  // the default's 1/8 of batch_rays
          "train.anneal_steps=10",
          "train.occupancy_warmup=16",
          "train.occupancy_every=8",
          "train.log_every=10"};
}

void BenchOptions::ApplyQuick() {
  identities = 1;
  ks = {3};
  methods = {"icef-prior", "warp-prior", "icef", "icef-no-conf", "icef-uniform", "warp", "nerface"};
  resolution = 32;
  test_views = 1;
  novel_per_tier = 1;
  steps = 20;
  time_budget_seconds = 0;
  // A tiny model (the user's --set overrides still come after these).
  const std::vector<std::string> tiny = TinyModelOverrides();
  overrides.insert(overrides.begin(), tiny.begin(), tiny.end());
}

void BenchOptions::ApplyValidation() {
  validation = true;
  identities = kDefaultValidationIdentities;
  first_identity_seed = kFirstValidationSeed;
  ks = {5};
  diverse = true;
  draw_resolution = true;
  methods = {"icef", "icef-prior"};
  // A pure step budget of `icef train`'s default (the model as a user trains it): tuning compares
  // runs, which a wall-clock cap on a busy machine would not make reproducible.
  steps = TrainConfig().steps;
  time_budget_seconds = 0;
}

std::string BenchOptions::IdentityRole() const {
  return validation ? "validation identities: for tuning and prior experiments, never reported as results"
                    : "test identities: never used to choose a default or a hyperparameter; tuning uses the "
                      "validation seeds " +
                          std::to_string(kFirstValidationSeed) + " and up (`icef bench --validation`)";
}

Status BenchOptions::Validate() const {
  if (out_dir.empty()) return Status::Error("bench: --out is required");
  if (identities < 1) return Status::Error("bench: --identities must be >= 1");
  const uint64_t last_seed = first_identity_seed + uint64_t(identities) - 1;
  if (validation && first_identity_seed < kFirstValidationSeed)
    return Status::Error("bench: --validation uses validation seeds (" +
                         std::to_string(kFirstValidationSeed) + " and up), got --first-seed " +
                         std::to_string(first_identity_seed));
  if (!validation && last_seed >= kFirstValidationSeed)
    return Status::Error("bench: seeds " + std::to_string(kFirstValidationSeed) +
                         " and up are validation identities; a test bench uses seeds below it (got seeds " +
                         std::to_string(first_identity_seed) + ".." + std::to_string(last_seed) +
                         "; add --validation for a validation bench)");
  if (replicates < 1) return Status::Error("bench: --replicates must be >= 1");
  if (ks.empty()) return Status::Error("bench: --k needs at least one value");
  for (int k : ks)
    if (k < 1) return Status::Error("bench: --k values must be >= 1, got " + std::to_string(k));
  if (methods.empty()) return Status::Error("bench: --methods needs at least one method");
  for (const std::string& m : methods)
    ICEF_RETURN_IF_ERROR(ParseMethod(m).status().WithContext("bench: --methods"));
  if (resolution < 16) return Status::Error("bench: --res must be >= 16");
  if (test_views < 1) return Status::Error("bench: test_views must be >= 1");
  if (novel_per_tier < 1) return Status::Error("bench: novel_per_tier must be >= 1");
  if (steps < 1) return Status::Error("bench: --steps must be >= 1");
  if (time_budget_seconds < 0) return Status::Error("bench: --time-budget must be >= 0");
  if (shard_count < 1 || shard_index < 0 || shard_index >= shard_count)
    return Status::Error("bench: --shard must be i/n with 0 <= i < n");
  return Status::Ok();
}

Json BenchOptions::ToJson() const {
  Json j;
  j["identities"] = identities;
  j["first_identity_seed"] = first_identity_seed;
  j["validation"] = validation;
  j["ks"] = ks;
  j["replicates"] = replicates;
  j["methods"] = methods;
  j["resolution"] = draw_resolution
                        ? Json("drawn per identity, 128-" + std::to_string(kMaxValidationResolution))
                        : Json(resolution);
  if (diverse) {
    synth::SceneAxes axes = synth::SceneAxes::All();
    axes.resolution = draw_resolution;
    j["scenes"] = "diverse (drawn per identity: " + axes.ToString() + ")";
  } else {
    j["scenes"] = "classic";
  }
  if (face_model != "procedural") j["face_model"] = face_model;
  j["test_views"] = test_views;
  j["novel_per_tier"] = novel_per_tier;
  j["steps"] = steps;
  j["time_budget_seconds"] = time_budget_seconds;
  j["config"] = config_path;
  j["overrides"] = overrides;
  j["shard"] = std::to_string(shard_index) + "/" + std::to_string(shard_count);
  return j;
}

std::string BenchOptions::ToString() const {
  return "BenchOptions(out=" + out_dir.string() + ", " + ToJson().dump() + ")";
}

Status ParseShard(const std::string& text, int* index, int* count) {
  int i = 0, n = 0;
  char extra = 0;
  if (std::sscanf(text.c_str(), "%d/%d%c", &i, &n, &extra) != 2 || n < 1 || i < 0 || i >= n)
    return Status::Error("--shard: expected i/n with 0 <= i < n (e.g. 0/3), got '" + text + "'");
  *index = i;
  *count = n;
  return Status::Ok();
}

Result<std::vector<int>> ParseIntList(const std::string& text, const std::string& what) {
  std::vector<int> out;
  std::stringstream s(text);
  std::string item;
  while (std::getline(s, item, ',')) {
    size_t used = 0;
    int v = 0;
    try {
      v = std::stoi(item, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used == 0 || used != item.size())
      return Status::Error(what + ": expected comma-separated integers, got '" + text + "'");
    out.push_back(v);
  }
  if (out.empty()) return Status::Error(what + ": expected comma-separated integers, got '" + text + "'");
  return out;
}

std::vector<RunId> PlanRuns(const BenchOptions& o) {
  std::vector<RunId> runs;
  for (int i = 0; i < o.identities; ++i)
    for (int k : o.ks)
      for (const std::string& m : o.methods)
        for (int r = 0; r < o.replicates; ++r)
          runs.push_back(RunId{o.first_identity_seed + uint64_t(i), k, m, r});
  return runs;
}

std::vector<RunId> ShardRuns(const std::vector<RunId>& runs, int index, int count) {
  std::vector<RunId> out;
  for (size_t i = static_cast<size_t>(index); i < runs.size(); i += static_cast<size_t>(count))
    out.push_back(runs[i]);
  return out;
}

namespace {

double Seconds(std::chrono::steady_clock::time_point since) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
}

// The dataset of (identity, K), synthesised on first use and cached in out/data/ (re-synthesised
// when the options written beside it differ).
Result<Dataset> EnsureDataset(const BenchOptions& o, uint64_t seed, int k, const Executor& executor,
                              std::ostream& log, bool interactive) {
  synth::SynthOptions so;
  so.out_dir = o.out_dir / "data" / ("id" + std::to_string(seed) + "_k" + std::to_string(k));
  so.identity_seed = seed;
  so.num_train = k;
  so.resolution = o.resolution;
  so.test_views = o.test_views;
  so.novel_per_tier = o.novel_per_tier;
  if (o.diverse) {
    so.vary = synth::SceneAxes::All();
    so.vary.resolution = o.draw_resolution;
    so.max_drawn_resolution = kMaxValidationResolution;
  }
  ICEF_RETURN_IF_ERROR(so.Validate());
  const fs::path stamp = so.out_dir / "synth_options.txt";
  const std::string want = so.ToString() + "\n";
  std::error_code ec;
  if (fs::exists(stamp, ec) && fs::exists(so.out_dir / "transforms_test.json", ec)) {
    Result<std::string> have = ReadFile(stamp);
    if (have.ok() && *have == want) return LoadDataset(so.out_dir);
  }
  ProgressBar bar("synth " + so.out_dir.filename().string(), synth::SynthImageCount(so), log, interactive);
  Dataset dataset;
  ICEF_RETURN_IF_ERROR(synth::SynthesizeDataset(so, executor, &bar, &dataset));
  ICEF_RETURN_IF_ERROR(WriteFileAtomic(stamp, want));
  return LoadDataset(so.out_dir);
}

// EnsureDataset, re-expressed in the bench's face model when it is not the procedural one (cached
// beside it as <name>_<face_model>, redone when the synthesised dataset was).
Result<Dataset> EnsureBenchDataset(const BenchOptions& o, uint64_t seed, int k, const Executor& executor,
                                   std::ostream& log, bool interactive) {
  ICEF_ASSIGN_OR_RETURN(const Dataset source, EnsureDataset(o, seed, k, executor, log, interactive));
  if (o.face_model == "procedural") return source;
  if (!o.reexpress) return Status::Error("bench: no re-expression for face model " + o.face_model);
  const fs::path dir = source.root.string() + "_" + o.face_model;
  std::error_code ec;
  const bool fresh = fs::exists(dir / "transforms_test.json", ec) &&
                     fs::last_write_time(dir / "transforms_test.json", ec) >=
                         fs::last_write_time(source.root / "synth_options.txt", ec);
  if (fresh) return LoadDataset(dir);
  fs::remove_all(dir, ec);
  // Flushed: a bench's log is read while it runs, often from a file.
  log << "bench: re-expressing " << source.root.filename().string() << " in " << o.face_model << std::endl;
  return o.reexpress(source, dir);
}

Result<RunConfig> MakeRunConfig(const BenchOptions& o, const RunId& id) {
  RunConfig config;
  if (!o.config_path.empty()) {
    ICEF_ASSIGN_OR_RETURN(config, RunConfig::FromFile(o.config_path));
  }
  config.train.checkpoint_every = 0;  // one checkpoint at the end (models are usually deleted)
  config.train.eval_every = 0;
  for (const std::string& a : o.overrides)
    ICEF_RETURN_IF_ERROR(config.ApplyOverride(a).WithContext("bench: --set"));
  config.model.method = id.method;
  config.train.steps = o.steps;
  config.train.time_budget_seconds = o.time_budget_seconds;
  config.train.seed = id.TrainSeed();
  config.train.threads = o.threads;
  ICEF_RETURN_IF_ERROR(config.Validate());
  return config;
}

// The networks shared by every evaluation of the bench.
struct BenchNetworks {
  std::optional<FaceIdentity> identity;
  std::optional<LpipsNet> lpips;
  std::string identity_note;
  EvalNetworks View() {
    EvalNetworks n;
    n.identity = identity ? &*identity : nullptr;
    n.lpips = lpips ? &*lpips : nullptr;
    n.identity_note = identity_note;
    return n;
  }
};

Result<BenchNetworks> LoadNetworks(const BenchOptions& o, std::ostream& log) {
  BenchNetworks n;
  FaceIdentityOptions fo;
  fo.model_dir = o.faceid_model_dir;
  Result<FaceIdentity> identity = FaceIdentity::Load(fo);
  if (identity.ok()) {
    n.identity = std::move(identity).value();
  } else {
    n.identity_note = identity.status().message();
    log << "bench: identity metrics unavailable: " << n.identity_note << "\n";
  }
  ICEF_ASSIGN_OR_RETURN(n.lpips, LoadLpipsIfConfigured(o.lpips_weights));
  return n;
}

// One run: train, evaluate, write runs/<name>/metrics.json.
Result<RunRecord> RunOne(const BenchOptions& o, const RunId& id, const Dataset& dataset,
                         BenchNetworks& networks, const Executor& executor, std::ostream& log,
                         bool interactive) {
  const fs::path run_dir = o.out_dir / "runs" / id.Name();
  const fs::path model_dir = run_dir / "model";
  std::error_code ec;
  fs::remove_all(model_dir, ec);  // a half-finished earlier attempt is redone from scratch
  ICEF_ASSIGN_OR_RETURN(const RunConfig config, MakeRunConfig(o, id));
  RunRecord record;
  record.id = id;
  const auto train_start = std::chrono::steady_clock::now();
  ICEF_ASSIGN_OR_RETURN(std::unique_ptr<Trainer> trainer, Trainer::Create(dataset, model_dir, config));
  ProgressBar train_bar("train " + id.Name(), config.train.steps, log, interactive);
  ICEF_ASSIGN_OR_RETURN(const TrainSummary summary, trainer->Run(
                                                        [&](const TrainProgress& p) {
                                                          char status[96];
                                                          std::snprintf(status, sizeof status,
                                                                        "loss %.4f psnr %.2f", p.terms.total,
                                                                        p.terms.psnr());
                                                          train_bar.Update(p.step, status);
                                                        },
                                                        nullptr));
  char done[128];
  std::snprintf(done, sizeof done, "%lld steps, batch psnr %.2f (%s)", static_cast<long long>(summary.steps),
                summary.final_batch_psnr, summary.stop_reason.c_str());
  train_bar.Finish(done);
  record.train_steps = summary.steps;
  record.train_seconds = Seconds(train_start);

  const auto eval_start = std::chrono::steady_clock::now();
  ProgressBar eval_bar("eval  " + id.Name(), static_cast<int64_t>(dataset.test.size()), log, interactive);
  EvalOptions eo;
  eo.out_dir = run_dir;
  ICEF_ASSIGN_OR_RETURN(record.metrics,
                        EvaluateModel(trainer->model(), dataset, eo, networks.View(), executor, &eval_bar));
  record.eval_seconds = Seconds(eval_start);
  trainer.reset();
  if (!o.keep_models) fs::remove_all(model_dir, ec);
  ICEF_RETURN_IF_ERROR(WriteFileAtomic(run_dir / "metrics.json", FormatJson(RunRecordJson(record))));
  return record;
}

}  // namespace

Status RunBench(const BenchOptions& o, std::ostream& log, bool interactive) {
  ICEF_RETURN_IF_ERROR(o.Validate());
  const auto start = std::chrono::steady_clock::now();
  std::error_code ec;
  fs::create_directories(o.out_dir / "runs", ec);
  if (ec) return Status::Error((o.out_dir / "runs").string() + ": cannot create directory: " + ec.message());
  ICEF_RETURN_IF_ERROR(WriteFileAtomic(o.out_dir / "bench.json", FormatJson(o.ToJson())));
  for (const RunId& id : PlanRuns(o)) ICEF_RETURN_IF_ERROR(MakeRunConfig(o, id).status());

  const std::vector<RunId> runs = ShardRuns(PlanRuns(o), o.shard_index, o.shard_count);
  std::vector<RunId> todo;
  for (const RunId& id : runs)
    if (!fs::exists(o.out_dir / "runs" / id.Name() / "metrics.json", ec)) todo.push_back(id);
  log << "bench: " << runs.size() << " runs in shard " << o.shard_index << "/" << o.shard_count << " ("
      << runs.size() - todo.size() << " already done), "
      << (o.draw_resolution
              ? "resolution drawn per identity (128-" + std::to_string(kMaxValidationResolution) + ")"
              : std::to_string(o.resolution) + "x" + std::to_string(o.resolution))
      << (o.diverse ? ", diverse scenes" : "") << ", "
      << (o.time_budget_seconds > 0
              ? "time budget " + ProgressBar::FormatDuration(o.time_budget_seconds) + ", up to "
              : std::string())
      << o.steps << " steps per run\n";
  const Executor executor(o.threads);
  BenchNetworks networks;
  if (!todo.empty()) {
    ICEF_ASSIGN_OR_RETURN(networks, LoadNetworks(o, log));
  }
  std::map<std::pair<uint64_t, int>, Dataset> datasets;
  for (size_t i = 0; i < todo.size(); ++i) {
    const RunId& id = todo[i];
    const double elapsed = Seconds(start);
    log << "bench: run " << i + 1 << "/" << todo.size() << " " << id.Name() << "  elapsed "
        << ProgressBar::FormatDuration(elapsed);
    if (i > 0) log << ", ETA " << ProgressBar::FormatDuration(elapsed / i * (todo.size() - i));
    log << std::endl;
    auto it = datasets.find({id.identity_seed, id.k});
    if (it == datasets.end()) {
      // Only one identity x K dataset is held at a time (runs are identity/K-major).
      datasets.clear();
      ICEF_ASSIGN_OR_RETURN(Dataset d,
                            EnsureBenchDataset(o, id.identity_seed, id.k, executor, log, interactive));
      it = datasets.emplace(std::make_pair(id.identity_seed, id.k), std::move(d)).first;
    }
    ICEF_ASSIGN_OR_RETURN(const RunRecord record,
                          RunOne(o, id, it->second, networks, executor, log, interactive));
    const TierMetrics& far = record.metrics.tiers[TierIndex(Tier::kFar)];
    char line[256];
    std::snprintf(line, sizeof line, "bench: %s far tier: psnr %s id_distance %s (train %s, eval %s)\n",
                  id.Name().c_str(), far.psnr ? std::to_string(*far.psnr).c_str() : "-",
                  far.id_distance ? std::to_string(*far.id_distance).c_str() : "-",
                  ProgressBar::FormatDuration(record.train_seconds).c_str(),
                  ProgressBar::FormatDuration(record.eval_seconds).c_str());
    log << line << std::flush;
  }

  ICEF_ASSIGN_OR_RETURN(const std::vector<RunRecord> records, ReadRunRecords(o.out_dir));
  ReportContext context;
  context.settings = o.ToJson();
  context.identity_role = o.IdentityRole();
  context.per_identity = o.validation;
  {
    const synth::SynthOptions defaults;
    context.tier_thresholds = std::array<double, 2>{defaults.near_threshold, defaults.far_threshold};
  }
  const double wall = Seconds(start);
  if (todo.size() == runs.size() && o.shard_count == 1) context.wall_seconds = wall;
  if (o.shard_count > 1)
    context.notes.push_back("Shard " + std::to_string(o.shard_index) + "/" + std::to_string(o.shard_count) +
                            " only; merge the shards with `icef bench merge`.");
  if (records.size() < PlanRuns(o).size())
    context.notes.push_back("Partial: " + std::to_string(records.size()) + " of " +
                            std::to_string(PlanRuns(o).size()) + " planned runs are in this directory.");
  ICEF_RETURN_IF_ERROR(WriteReport(o.out_dir, records, context));
  log << "bench: " << todo.size() << " runs in " << ProgressBar::FormatDuration(wall)
      << "; report: " << (o.out_dir / "report.md").string() << " (LaTeX tables: report.tex)\n";
  for (const std::string& line : Verdict(AggregateRuns(records))) log << "  " << line << "\n";
  return Status::Ok();
}

namespace {

// What the inputs of a merge share: their settings (bench.json less what varies between shards),
// every K and method any of them ran, and each run's metrics.json (run name -> text, source).
struct MergeInputs {
  std::optional<Json> settings;
  Json union_parts = Json::object();  // "ks", "methods": every value any input ran, in first-seen order
  std::map<std::string, std::pair<std::string, fs::path>> runs;
};

// One input's bench.json into `m`: which shard, which identities, which methods and Ks or how many
// training replicates a directory ran does not make it another bench: benches of the same protocol
// over other identity seeds, methods or frame counts merge like shards; the merged bench.json lists
// every method and K of its inputs.
Status MergeSettings(const fs::path& in, const fs::path& first, MergeInputs* m) {
  ICEF_ASSIGN_OR_RETURN(Json s, ReadJsonFile(in / "bench.json"));
  Json parts = Json::object();
  if (s.is_object()) {
    for (const char* key : {"ks", "methods"})
      if (s.contains(key)) parts[key] = s[key];
    for (const char* key : {"shard", "identities", "first_identity_seed", "replicates", "ks", "methods"})
      s.erase(key);
  }
  if (!m->settings) {
    m->settings = s;
  } else if (*m->settings != s) {
    return Status::Error((in / "bench.json").string() + ": settings differ from " +
                         (first / "bench.json").string() + " (shards of different benches?)");
  }
  for (const auto& [key, values] : parts.items()) {
    if (!values.is_array()) continue;
    Json& all = m->union_parts[key];
    if (!all.is_array()) all = Json::array();
    for (const Json& v : values)
      if (std::find(all.begin(), all.end(), v) == all.end()) all.push_back(v);
  }
  return Status::Ok();
}

// One input's runs into `m`. The same run in two inputs is fine when its metrics agree (training
// and evaluation are deterministic for a step budget; only the timings differ), else the first is kept.
Status MergeRuns(const fs::path& in, MergeInputs* m, std::ostream& log) {
  ICEF_ASSIGN_OR_RETURN(const std::vector<RunRecord> records, ReadRunRecords(in));
  for (const RunRecord& r : records) {
    const fs::path src = in / "runs" / r.id.Name() / "metrics.json";
    ICEF_ASSIGN_OR_RETURN(const std::string text, ReadFile(src));
    const auto [it, inserted] = m->runs.emplace(r.id.Name(), std::make_pair(text, src));
    if (inserted) continue;
    ICEF_ASSIGN_OR_RETURN(const RunRecord first, ReadRunRecord(it->second.second));
    if (first.metrics.ToJson() != r.metrics.ToJson())
      log << "bench merge: warning: " << src.string() << " differs from " << it->second.second.string()
          << " (a time budget makes runs differ); keeping the first\n";
  }
  log << "bench merge: " << records.size() << " runs from " << in.string() << "\n";
  return Status::Ok();
}

// The merged report's context; writes the merged bench.json when the inputs had settings.
Result<ReportContext> MergedContext(MergeInputs& m, size_t num_inputs, const fs::path& out_dir) {
  ReportContext context;
  for (const auto& [name, entry] : m.runs) context.run_dirs[name] = entry.second.parent_path();
  if (m.settings) {
    for (const auto& [key, values] : m.union_parts.items()) (*m.settings)[key] = values;
    context.settings = *m.settings;
    ICEF_RETURN_IF_ERROR(WriteFileAtomic(out_dir / "bench.json", FormatJson(*m.settings)));
    BenchOptions role;
    role.validation = m.settings->value("validation", false);
    context.identity_role = role.IdentityRole();
    context.per_identity = role.validation;
  }
  const synth::SynthOptions defaults;
  context.tier_thresholds = std::array<double, 2>{defaults.near_threshold, defaults.far_threshold};
  context.notes.push_back(
      "Merged from " + std::to_string(num_inputs) +
      " bench directories (renders stay there; the worst identities' training views are drawn "
      "from them).");
  return context;
}

}  // namespace

Status MergeBench(const std::vector<fs::path>& inputs, const fs::path& out_dir, std::ostream& log) {
  if (inputs.empty()) return Status::Error("bench merge: no input directories");
  std::error_code ec;
  fs::create_directories(out_dir / "runs", ec);
  if (ec) return Status::Error((out_dir / "runs").string() + ": cannot create directory: " + ec.message());
  MergeInputs m;
  for (const fs::path& in : inputs) {
    if (!fs::is_directory(in / "runs", ec))
      return Status::Error(in.string() + ": not a bench directory (no runs/)");
    if (fs::exists(in / "bench.json", ec)) ICEF_RETURN_IF_ERROR(MergeSettings(in, inputs.front(), &m));
    ICEF_RETURN_IF_ERROR(MergeRuns(in, &m, log));
  }
  for (const auto& [name, entry] : m.runs) {
    fs::create_directories(out_dir / "runs" / name, ec);
    ICEF_RETURN_IF_ERROR(WriteFileAtomic(out_dir / "runs" / name / "metrics.json", entry.first));
  }
  ICEF_ASSIGN_OR_RETURN(const std::vector<RunRecord> records, ReadRunRecords(out_dir));
  ICEF_ASSIGN_OR_RETURN(const ReportContext context, MergedContext(m, inputs.size(), out_dir));
  ICEF_RETURN_IF_ERROR(WriteReport(out_dir, records, context));
  log << "bench merge: " << records.size() << " runs; report: " << (out_dir / "report.md").string()
      << " (LaTeX tables: report.tex)\n";
  for (const std::string& line : Verdict(AggregateRuns(records))) log << "  " << line << "\n";
  return Status::Ok();
}

}  // namespace icef::eval
