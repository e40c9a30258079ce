#include "icef/app/real_bench_app.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <set>
#include <sstream>
#include <system_error>

#include "icef/app/track_app.h"
#include "icef/core/parallel.h"
#include "icef/core/progress.h"
#include "icef/data/dataset.h"
#include "icef/data/frame_coverage.h"
#include "icef/eval/face_identity.h"
#include "icef/eval/lpips.h"
#include "icef/eval/real_protocol.h"
#include "icef/io/atomic_file.h"
#include "icef/model/method.h"
#include "icef/study/bench_protocol.h"
#include "icef/study/real_report.h"
#include "icef/synth/synthesize.h"
#include "icef/train/trainer.h"
#include "icef/video/video_reader.h"

namespace fs = std::filesystem;

namespace icef {

namespace {

double Seconds(std::chrono::steady_clock::time_point since) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
}

bool IsDatasetDir(const fs::path& p) {
  std::error_code ec;
  return fs::exists(p / "transforms_train.json", ec);
}

// A source's name: its file or folder name without extension, made unique among the sources.
std::vector<std::string> SourceNames(const std::vector<fs::path>& sources) {
  std::vector<std::string> names;
  std::set<std::string> used;
  for (const fs::path& s : sources) {
    fs::path p = s;
    if (p.filename().empty()) p = p.parent_path();  // "photos/" -> "photos"
    std::string base = p.stem().string();
    for (char& c : base)
      if (!std::isalnum(static_cast<unsigned char>(c)) && c != '-') c = '-';
    if (base.empty()) base = "source";
    std::string name = base;
    for (int n = 2; used.count(name); ++n) name = base + "-" + std::to_string(n);
    used.insert(name);
    names.push_back(name);
  }
  return names;
}

// How many photos a folder holds.
Result<int> CountPhotos(const fs::path& dir) {
  ICEF_ASSIGN_OR_RETURN(const std::vector<fs::path> photos, track::ExpandPhotoArguments({dir}));
  return static_cast<int>(photos.size());
}

// The source tracked once (kept when its stamp matches): OUT/sources/<name>/tracked.
Result<Dataset> TrackSource(const RealBenchOptions& o, const fs::path& source, const fs::path& dir,
                            eval::RealSourceInfo* info, std::ostream& log) {
  if (IsDatasetDir(source)) {
    info->origin = source.string() + " (tracked dataset)";
    return LoadDataset(source);
  }
  const int max_k = *std::max_element(o.ks.begin(), o.ks.end());
  const int min_k = *std::min_element(o.ks.begin(), o.ks.end());
  TrackAppOptions t;
  t.photos = {source};
  t.out = dir / "tracked";
  t.threads = o.threads;
  t.track.resolution = o.resolution;
  t.track.face_model = *track::ParseTrackFaceModel(o.face_model);  // checked by Validate
  t.track.skip_bad = true;
  t.interactive = o.interactive;
  if (LooksLikeVideo(source)) {
    t.max_frames = o.video_frames;
    t.track.num_train = std::min(max_k, o.video_frames - o.test_frames);
    t.track.num_test = o.test_frames;
    info->origin = source.string() + " (video, " + std::to_string(o.video_frames) + " frames tracked)";
  } else {
    ICEF_ASSIGN_OR_RETURN(const int n, CountPhotos(source));
    const int test = std::min(o.test_frames, n - min_k);
    if (test < 1)
      return Status::Error(source.string() + ": " + std::to_string(n) + " photos: too few to train on " +
                           std::to_string(min_k) + " and hold one out");
    t.track.num_train = std::min(max_k, n - test);
    t.track.num_test = test;
    info->origin = source.string() + " (" + std::to_string(n) + " photos)";
  }
  const std::string stamp = t.track.ToString() + " max_frames=" + std::to_string(t.max_frames) + "\n";
  std::error_code ec;
  if (IsDatasetDir(t.out)) {
    Result<std::string> have = ReadFile(dir / "track_options.txt");
    if (have.ok() && *have == stamp) return LoadDataset(t.out);
  }
  // Tracked anew: the K datasets and runs made from an earlier tracking are stale.
  fs::remove_all(dir, ec);
  const fs::path runs = dir.parent_path().parent_path() / "runs";
  for (const auto& entry : fs::directory_iterator(runs, ec))
    if (entry.path().filename().string().rfind(dir.filename().string() + "_k", 0) == 0)
      fs::remove_all(entry.path(), ec);
  fs::create_directories(dir, ec);
  if (ec) return Status::Error(dir.string() + ": cannot create directory: " + ec.message());
  ICEF_RETURN_IF_ERROR(RunTrack(t, log).WithContext(source.string()));
  ICEF_RETURN_IF_ERROR(WriteFileAtomic(dir / "track_options.txt", stamp));
  return LoadDataset(t.out);
}

// The K-frame dataset of a tracked source: the K training frames of best coverage, every
// held-out frame (delta and tier recomputed against them), images copied.
Result<Dataset> MakeKDataset(const Dataset& pool, int k, const fs::path& out) {
  if (!IsDatasetDir(out)) {
    std::vector<CoverageCandidate> candidates;
    for (const Frame& f : pool.train) candidates.push_back(CandidateOfFrame(f, pool.expression_names));
    std::vector<int> chosen = ChooseCoverageFrames(candidates, k);
    std::sort(chosen.begin(), chosen.end());
    Dataset d = pool;
    d.train.clear();
    for (const int i : chosen) d.train.push_back(pool.train[i]);
    d.val.clear();
    const std::array<double, 2> thresholds = pool.tier_thresholds.value_or(
        std::array<double, 2>{synth::SynthOptions().near_threshold, synth::SynthOptions().far_threshold});
    for (Frame& f : d.test) {
      f.delta = eval::NearestTrainingExpression(d, f.expression).second;
      f.tier = synth::TierForDelta(*f.delta, thresholds[0], thresholds[1]);
    }
    ICEF_RETURN_IF_ERROR(CreateDirectoryAtomic(out, [&](const fs::path& tmp) -> Status {
      d.root = tmp;
      for (const auto* split : {&d.train, &d.test})
        for (const Frame& f : *split) {
          std::error_code ec;
          fs::create_directories((tmp / f.file_path).parent_path(), ec);
          fs::copy_file(pool.root / f.file_path, tmp / f.file_path, fs::copy_options::overwrite_existing, ec);
          if (ec) return Status::Error((pool.root / f.file_path).string() + ": cannot copy: " + ec.message());
        }
      return SaveDataset(d);
    }));
  }
  return LoadDataset(out);
}

Result<RunConfig> MakeConfig(const RealBenchOptions& o, const std::string& method) {
  RunConfig config;
  if (!o.config_path.empty()) {
    ICEF_ASSIGN_OR_RETURN(config, RunConfig::FromFile(o.config_path));
  }
  config.train.checkpoint_every = 0;
  config.train.eval_every = 0;
  for (const std::string& a : o.overrides) ICEF_RETURN_IF_ERROR(config.ApplyOverride(a).WithContext("--set"));
  config.model.method = method;
  config.train.steps = o.steps;
  config.train.time_budget_seconds = o.time_budget_seconds;
  config.train.threads = o.threads;
  ICEF_RETURN_IF_ERROR(config.Validate());
  return config;
}

Result<eval::RealRunRecord> RunOne(const RealBenchOptions& o, eval::RealRunRecord record,
                                   const Dataset& dataset, const eval::EvalNetworks& networks,
                                   const Executor& executor, std::ostream& log) {
  const fs::path model_dir = record.run_dir / "model";
  std::error_code ec;
  fs::remove_all(model_dir, ec);
  ICEF_ASSIGN_OR_RETURN(const RunConfig config, MakeConfig(o, record.method));
  const auto start = std::chrono::steady_clock::now();
  ICEF_ASSIGN_OR_RETURN(std::unique_ptr<Trainer> trainer, Trainer::Create(dataset, model_dir, config));
  ProgressBar bar("train " + record.Name(), config.train.steps, log, o.interactive);
  ICEF_ASSIGN_OR_RETURN(const TrainSummary summary,
                        trainer->Run([&](const TrainProgress& p) { bar.Update(p.step); }, nullptr));
  bar.Finish(std::to_string(summary.steps) + " steps (" + summary.stop_reason + ")");
  record.train_steps = summary.steps;
  record.train_seconds = Seconds(start);
  ProgressBar eval_bar("eval  " + record.Name(), static_cast<int64_t>(dataset.test.size()), log,
                       o.interactive);
  eval::RealEvalOptions eo;
  eo.out_dir = record.run_dir;
  ICEF_ASSIGN_OR_RETURN(record.metrics,
                        eval::EvaluateReal(trainer->model(), dataset, eo, networks, executor, &eval_bar));
  eval_bar.Finish();
  trainer.reset();
  if (!o.keep_models) fs::remove_all(model_dir, ec);
  ICEF_RETURN_IF_ERROR(WriteFileAtomic(record.run_dir / "metrics.json", FormatJson(record.ToJson())));
  return record;
}

}  // namespace

void RealBenchOptions::ApplyQuick() {
  ks = {3};
  test_frames = 2;
  video_frames = 8;
  resolution = 64;
  steps = 20;
  time_budget_seconds = 0;
  const std::vector<std::string> tiny = eval::TinyModelOverrides();
  overrides.insert(overrides.begin(), tiny.begin(), tiny.end());
}

Status RealBenchOptions::Validate() const {
  if (sources.empty())
    return Status::Error("--real: give at least one source (a video, a photo folder or a dataset)");
  if (out_dir.empty()) return Status::Error("--out: required");
  if (ks.empty()) return Status::Error("--k: give at least one K");
  for (const int k : ks)
    if (k < 1) return Status::Error("--k: every K must be >= 1, got " + std::to_string(k));
  if (test_frames < 1) return Status::Error("--test: must be >= 1");
  if (video_frames < *std::max_element(ks.begin(), ks.end()) + test_frames)
    return Status::Error("--video-frames: must be at least the largest K plus --test");
  if (steps < 1) return Status::Error("--steps: must be >= 1");
  if (!track::ParseTrackFaceModel(face_model))
    return Status::Error("--face-model: expected procedural or ict, got \"" + face_model + "\"");
  for (const std::string& m : methods)
    if (!ParseMethod(m).ok()) return Status::Error("--method: unknown method '" + m + "'");
  std::error_code ec;
  for (const fs::path& s : sources)
    if (!fs::exists(s, ec)) return Status::Error(s.string() + ": no such file or directory");
  return Status::Ok();
}

std::string RealBenchOptions::ToString() const {
  std::ostringstream os;
  os << "resolution " << resolution << ", " << steps << " steps per run"
     << (time_budget_seconds > 0 ? " (at most " + ProgressBar::FormatDuration(time_budget_seconds) + ")" : "")
     << ", K in {";
  for (size_t i = 0; i < ks.size(); ++i) os << (i ? ", " : "") << ks[i];
  os << "}, methods ";
  for (size_t i = 0; i < methods.size(); ++i) os << (i ? ", " : "") << methods[i];
  os << ", " << test_frames << " held-out frames per source, " << video_frames << " frames tracked per video"
     << ", face model " << face_model;
  if (!overrides.empty()) os << ", " << overrides.size() << " config overrides";
  return os.str();
}

Status RunRealBench(const RealBenchOptions& o, std::ostream& log) {
  ICEF_RETURN_IF_ERROR(o.Validate());
  std::error_code ec;
  fs::create_directories(o.out_dir / "runs", ec);
  if (ec) return Status::Error((o.out_dir / "runs").string() + ": cannot create directory: " + ec.message());
  const Executor executor(o.threads);
  eval::FaceIdentityOptions fo;
  fo.model_dir = o.faceid_model_dir;
  std::optional<eval::FaceIdentity> identity;
  Result<eval::FaceIdentity> loaded = eval::FaceIdentity::Load(fo);
  eval::EvalNetworks networks;
  if (loaded.ok()) {
    identity = std::move(loaded).value();
    networks.identity = &*identity;
  } else {
    networks.identity_note = loaded.status().message();
    log << "bench --real: identity distance unavailable: " << networks.identity_note << "\n";
  }
  ICEF_ASSIGN_OR_RETURN(const std::optional<eval::LpipsNet> lpips,
                        eval::LoadLpipsIfConfigured(o.lpips_weights));
  networks.lpips = lpips ? &*lpips : nullptr;

  eval::RealReportContext context;
  context.settings = o.ToString();
  std::vector<eval::RealRunRecord> records;
  const std::vector<std::string> names = SourceNames(o.sources);
  for (size_t s = 0; s < o.sources.size(); ++s) {
    eval::RealSourceInfo info;
    info.name = names[s];
    const fs::path source_dir = o.out_dir / "sources" / names[s];
    log << "bench --real: source " << names[s] << ": " << o.sources[s].string() << "\n";
    ICEF_ASSIGN_OR_RETURN(const Dataset pool, TrackSource(o, o.sources[s], source_dir, &info, log));
    info.pool_train = static_cast<int>(pool.train.size());
    info.test = static_cast<int>(pool.test.size());
    if (pool.test.empty()) return Status::Error(o.sources[s].string() + ": no held-out frames");
    for (const int k : o.ks) {
      if (k > info.pool_train) {
        info.notes.push_back("K = " + std::to_string(k) + " left out: " + std::to_string(info.pool_train) +
                             " training frames");
        continue;
      }
      ICEF_ASSIGN_OR_RETURN(const Dataset dataset,
                            MakeKDataset(pool, k, source_dir / ("k" + std::to_string(k))));
      for (const std::string& method : o.methods) {
        eval::RealRunRecord record;
        record.source = names[s];
        record.k = k;
        record.method = method;
        record.dataset = dataset.root;
        record.run_dir = o.out_dir / "runs" / record.Name();
        const fs::path metrics = record.run_dir / "metrics.json";
        if (fs::exists(metrics, ec)) {
          ICEF_ASSIGN_OR_RETURN(const std::string text, ReadFile(metrics));
          ICEF_ASSIGN_OR_RETURN(const Json json, ParseJson(text, metrics.string()));
          ICEF_ASSIGN_OR_RETURN(eval::RealRunRecord done,
                                eval::RealRunRecord::FromJson(json, metrics.string()));
          done.run_dir = record.run_dir;
          records.push_back(std::move(done));
          continue;
        }
        ICEF_ASSIGN_OR_RETURN(eval::RealRunRecord finished,
                              RunOne(o, record, dataset, networks, executor, log));
        char line[200];
        std::snprintf(line, sizeof line,
                      "  %s: face PSNR %.2f dB (still %.2f), real_expr_gain %.3f, %.0f s training",
                      finished.Name().c_str(), finished.metrics.means.face_psnr.value_or(NAN),
                      finished.metrics.means.face_psnr_nearest.value_or(NAN),
                      finished.metrics.means.real_expr_gain.value_or(NAN), finished.train_seconds);
        log << line << "\n";
        records.push_back(std::move(finished));
      }
    }
    context.sources.push_back(std::move(info));
  }
  ICEF_RETURN_IF_ERROR(eval::WriteRealReport(o.out_dir, records, context));
  log << "bench --real: wrote " << (o.out_dir / "report.md").string()
      << ", report.json, report.tex, plots/\n";
  return Status::Ok();
}

}  // namespace icef
