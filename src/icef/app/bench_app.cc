#include "icef/app/bench_app.h"

#include "icef/track/dataset_retrack.h"

namespace icef {

Status BenchAppOptions::Validate() const {
  ICEF_ASSIGN_OR_RETURN(const eval::BenchOptions resolved, ResolveBenchOptions(*this));
  return resolved.Validate();
}

Result<eval::BenchOptions> ResolveBenchOptions(const BenchAppOptions& a) {
  eval::BenchOptions o = a.base;
  if (a.identities) o.identities = *a.identities;
  if (a.first_seed) o.first_identity_seed = *a.first_seed;
  if (a.resolution) o.resolution = *a.resolution;
  if (a.test_views) o.test_views = *a.test_views;
  if (a.novel_per_tier) o.novel_per_tier = *a.novel_per_tier;
  if (a.steps) o.steps = *a.steps;
  if (a.time_budget) o.time_budget_seconds = *a.time_budget;
  if (a.validation) {
    o.ApplyValidation();
    // Options given explicitly win over the validation settings.
    if (a.identities) o.identities = *a.identities;
    if (a.first_seed) o.first_identity_seed = *a.first_seed;
    if (a.resolution) o.draw_resolution = false;
    if (a.steps) o.steps = *a.steps;
    if (a.time_budget) o.time_budget_seconds = *a.time_budget;
  }
  if (a.quick) {
    const std::vector<std::string> user = o.overrides;
    o.overrides.clear();
    o.ApplyQuick();
    if (o.validation) o.methods = {"icef", "icef-prior"}, o.ks = {5};  // the validation suite, tiny
    // Options given explicitly win over the quick settings.
    if (a.identities) o.identities = *a.identities;
    if (a.resolution) o.resolution = *a.resolution;
    o.draw_resolution = false;  // quick: always the tiny resolution
    if (a.test_views) o.test_views = *a.test_views;
    if (a.novel_per_tier) o.novel_per_tier = *a.novel_per_tier;
    if (a.steps) o.steps = *a.steps;
    if (a.time_budget) o.time_budget_seconds = *a.time_budget;
    o.overrides.insert(o.overrides.end(), user.begin(), user.end());
  }
  // --steps alone is a pure step budget (reproducible); the default caps steps by time.
  if (a.steps && !a.time_budget) o.time_budget_seconds = 0;
  o.out_dir = a.out;
  if (!a.ks.empty()) {
    ICEF_ASSIGN_OR_RETURN(o.ks, eval::ParseIntList(a.ks, "--k"));
  }
  if (!a.methods.empty()) o.methods = a.methods;
  if (!a.shard.empty()) ICEF_RETURN_IF_ERROR(eval::ParseShard(a.shard, &o.shard_index, &o.shard_count));
  return o;
}

Result<RealBenchOptions> ResolveRealBenchOptions(const BenchAppOptions& a) {
  RealBenchOptions r;
  r.sources = a.real;
  r.out_dir = a.out;
  if (a.quick) r.ApplyQuick();
  if (!a.ks.empty()) {
    ICEF_ASSIGN_OR_RETURN(r.ks, eval::ParseIntList(a.ks, "--k"));
  }
  if (!a.methods.empty()) r.methods = a.methods;
  if (a.real_test_frames) r.test_frames = *a.real_test_frames;
  if (a.video_frames) r.video_frames = *a.video_frames;
  if (a.real_face_model) r.face_model = *a.real_face_model;
  if (a.resolution) r.resolution = *a.resolution;
  if (a.steps) r.steps = *a.steps;
  if (a.time_budget) r.time_budget_seconds = *a.time_budget;
  r.config_path = a.base.config_path;
  r.overrides.insert(r.overrides.end(), a.base.overrides.begin(), a.base.overrides.end());
  r.threads = a.base.threads;
  r.faceid_model_dir = a.base.faceid_model_dir;
  r.lpips_weights = a.base.lpips_weights;
  r.keep_models = a.base.keep_models;
  r.interactive = a.interactive;
  return r;
}

Status RunBench(const BenchAppOptions& a, std::ostream& out) {
  if (!a.merge.empty()) {
    if (a.out.empty()) return Status::Error("bench merge: --out is required");
    return eval::MergeBench(a.merge, a.out, out);
  }
  if (!a.real.empty()) {
    ICEF_ASSIGN_OR_RETURN(const RealBenchOptions real, ResolveRealBenchOptions(a));
    return RunRealBench(real, out);
  }
  if (a.real_test_frames || a.video_frames)
    return Status::Error("--test and --video-frames go with --real (synthetic benches: --test-views)");
  ICEF_ASSIGN_OR_RETURN(eval::BenchOptions options, ResolveBenchOptions(a));
  if (a.real_face_model && *a.real_face_model != "procedural") {
    // The synthetic datasets re-expressed as `icef track --keep-cameras --face-model ict --landmarks
    // model` would: the generator's exact landmarks, ICT fitted among the known cameras.
    options.face_model = *a.real_face_model;
    options.reexpress = [](const Dataset& source, const std::filesystem::path& dir) -> Result<Dataset> {
      track::RetrackOptions ro;
      ro.landmarks = track::RetrackLandmarks::kDatasetModel;
      ro.face_model = track::TrackFaceModel::kIct;
      ICEF_ASSIGN_OR_RETURN(const track::RetrackResult result,
                            track::RetrackDataset(source, ro, Executor(0)));
      ICEF_RETURN_IF_ERROR(track::WriteRetrackedDataset(result, dir));
      return LoadDataset(dir);
    };
  }
  return eval::RunBench(options, out, a.interactive);
}

}  // namespace icef
