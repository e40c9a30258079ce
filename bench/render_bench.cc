// What users wait for, on the synthetic K = 5 subject of identity seed 1 with the default config
// (the default method): `icef render` / `icef eval` per image, a 128x128 and a 256x256 frame (the
// default one ray per pixel) at a far expression, with the occupancy grid built for that expression
// (the default), with the training grid, and with rays composited as deep as training does; building
// that grid alone; `icef train`'s step (BM_TrainStep: rays/s, samples/s and steps/s of the full
// default training step) and the first 300 steps of a fresh run (BM_TrainWarmup); and `icef eval`
// per test frame (BM_EvalFrame). The render model is
// trained once per process (1000 steps, about a minute on 2 cores: as trained as the models users
// render; at 300 steps it is still semi-transparent fog that every ray marches through), so the
// first benchmark that needs it pays for it; the training step runs on a trainer of its own, warmed
// up past the occupancy grid's warm-up (300 steps). Compare with BM_GemmFp32 of the same run (the machine's
// matrix-multiply rate).
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <filesystem>
#include <memory>

#include "icef/eval/evaluate.h"
#include "icef/face/ict_model.h"
#include "icef/model/render_image.h"
#include "icef/model/trained_model.h"
#include "icef/synth/synthesize.h"
#include "icef/track/dataset_retrack.h"
#include "icef/train/trainer.h"

namespace {

struct Subject {
  icef::Dataset dataset;
  std::unique_ptr<icef::Trainer> trainer;
  // The same model loaded as `icef render --set model.render.transmittance_eps=1e-4` would: renders
  // composite rays as deep as training does (the render threshold's before/after).
  std::unique_ptr<icef::AvatarModel> deep;
  // The same model sampling rays at the training count (`--set model.render.sample_factor=1`, the
  // renders before the default became 2).
  std::unique_ptr<icef::AvatarModel> sparse;
  std::string error;
  std::filesystem::path dir;  // removed at exit
  ~Subject() {
    trainer.reset();
    deep.reset();
    sparse.reset();
    std::error_code ec;
    if (!dir.empty()) std::filesystem::remove_all(dir, ec);
  }
};

icef::Status Train(Subject* s) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("icef_render_bench_" + std::to_string(::getpid()));
  s->dir = dir;
  icef::synth::SynthOptions so;
  so.out_dir = dir / "data";
  ICEF_RETURN_IF_ERROR(icef::synth::SynthesizeDataset(so, icef::Executor(2)));
  ICEF_ASSIGN_OR_RETURN(s->dataset, icef::LoadDataset(so.out_dir));
  icef::RunConfig config;
  config.train.steps = 1000;
  config.train.threads = 2;
  config.train.checkpoint_every = 0;
  ICEF_ASSIGN_OR_RETURN(s->trainer, icef::Trainer::Create(s->dataset, dir / "model", config));
  ICEF_RETURN_IF_ERROR(s->trainer->Run(nullptr, nullptr).status());
  ICEF_ASSIGN_OR_RETURN(
      icef::TrainedModel deep,
      icef::LoadTrainedModel(dir / "model", icef::Executor(2), {"model.render.transmittance_eps=1e-4"}));
  s->deep = std::move(deep.model);
  ICEF_ASSIGN_OR_RETURN(icef::TrainedModel sparse, icef::LoadTrainedModel(dir / "model", icef::Executor(2),
                                                                          {"model.render.sample_factor=1"}));
  s->sparse = std::move(sparse.model);
  return icef::Status::Ok();
}

const Subject& TrainedSubject() {
  static Subject subject;
  static const bool done = [] {
    if (icef::Status st = Train(&subject); !st.ok()) subject.error = st.message();
    return true;
  }();
  (void)done;
  return subject;
}

// The first far-tier test frame of the subject.
const icef::Frame& FarFrame(const Subject& s) {
  for (const icef::Frame& f : s.dataset.test)
    if (f.tier == icef::Tier::kFar) return f;
  return s.dataset.test.back();
}

// Arg: 0 = the grid of the rendered expression (default), 1 = the training grid, 2 = the default
// grid with rays composited to the training threshold 1e-4 instead of model.render.transmittance_eps,
// 3 = the default grid with rays sampled at the training count (model.render.sample_factor = 1).
void BM_RenderImage128(benchmark::State& state) {
  const Subject& s = TrainedSubject();
  if (!s.error.empty()) return state.SkipWithError(s.error.c_str());
  const icef::Frame& frame = FarFrame(s);
  const icef::Executor executor(2);
  const auto mode =
      state.range(0) == 1 ? icef::RenderOccupancyMode::kTraining : icef::RenderOccupancyMode::kExpression;
  const icef::AvatarModel& model = state.range(0) == 2   ? *s.deep
                                   : state.range(0) == 3 ? *s.sparse
                                                         : s.trainer->model();
  int64_t samples = 0;
  for (auto _ : state) {
    const icef::RenderedImage img =
        icef::RenderImage(model, frame.camera, frame.expression, s.dataset.background, executor, mode);
    samples += img.samples_evaluated;
  }
  state.counters["frames/s"] =
      benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
  state.counters["samples/frame"] = static_cast<double>(samples) / static_cast<double>(state.iterations());
}
BENCHMARK(BM_RenderImage128)
    ->ArgName("variant")
    ->Arg(0)
    ->Arg(1)
    ->Arg(2)
    ->Arg(3)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// A 256x256 frame of the same view (intrinsics scaled by 2).
void BM_RenderImage256(benchmark::State& state) {
  const Subject& s = TrainedSubject();
  if (!s.error.empty()) return state.SkipWithError(s.error.c_str());
  const icef::Frame& frame = FarFrame(s);
  icef::Intrinsics k = frame.camera.intrinsics();
  k.width *= 2, k.height *= 2, k.fl_x *= 2, k.fl_y *= 2, k.cx *= 2, k.cy *= 2;
  const icef::Camera camera(k, frame.camera.world_from_cam());
  const icef::Executor executor(2);
  for (auto _ : state)
    benchmark::DoNotOptimize(icef::RenderImage(s.trainer->model(), camera, frame.expression,
                                               s.dataset.background, executor,
                                               icef::RenderOccupancyMode::kExpression));
  state.counters["frames/s"] =
      benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_RenderImage256)->Unit(benchmark::kMillisecond)->UseRealTime();

// icef train's full default step (batch, forward, every loss, backward, Adam, schedules, and the
// occupancy-grid update every train.occupancy_every steps) on 2 threads, after warm-up steps of a
// fresh trainer past train.occupancy_warmup, so that the timed steps are those of most of a run.
// bf16:1 is the default config (model.bf16_training: the MLP products of training in BF16 with FP32
// sums); bf16:0 the same step in FP32. composited:1 is the default (only the samples the pixel rays
// composite run the colour MLP and the shading normals: AvatarModel::TrainForwardBackward);
// composited:0 colours every sample, as training did before.
// The timed part of BM_TrainStep and BM_TrainStepIct: a fresh trainer on `dataset` warmed up past
// train.occupancy_warmup (44 steps more), then one step per iteration; steps/s, rays/s, samples/s.
void TimeTrainSteps(benchmark::State& state, const icef::Dataset& dataset, const icef::RunConfig& config,
                    bool composited_only, const std::string& name) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("icef_" + name + "_bench_" + std::to_string(::getpid()));
  auto trainer = icef::Trainer::Create(dataset, dir, config);
  if (!trainer.ok()) return state.SkipWithError(trainer.status().message().c_str());
  (*trainer)->model().set_color_composited_only(composited_only);
  for (int i = 0; i < config.train.occupancy_warmup + 44; ++i)
    if (!(*trainer)->Step().ok()) return state.SkipWithError("warm-up step failed");
  int64_t samples = 0;
  for (auto _ : state) {
    const icef::Result<icef::LossTerms> terms = (*trainer)->Step();
    if (!terms.ok()) return state.SkipWithError(terms.status().message().c_str());
    samples += terms->samples;
  }
  const double steps = static_cast<double>(state.iterations());
  state.counters["steps/s"] = benchmark::Counter(steps, benchmark::Counter::kIsRate);
  state.counters["rays/s"] = benchmark::Counter(steps * config.train.batch_rays, benchmark::Counter::kIsRate);
  state.counters["samples/s"] = benchmark::Counter(static_cast<double>(samples), benchmark::Counter::kIsRate);
  trainer->reset();
  std::filesystem::remove_all(dir);
}

void BM_TrainStep(benchmark::State& state) {
  const Subject& s = TrainedSubject();
  if (!s.error.empty()) return state.SkipWithError(s.error.c_str());
  icef::RunConfig config;
  config.model.bf16_training = state.range(0) != 0;
  config.train.steps = 1000000;
  config.train.threads = 2;
  config.train.checkpoint_every = 0;
  TimeTrainSteps(state, s.dataset, config, state.range(1) != 0, "train");
}
BENCHMARK(BM_TrainStep)
    ->ArgNames({"bf16", "composited"})
    ->Args({0, 1})
    ->Args({1, 0})
    ->Args({1, 1})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MinTime(3.0);

// BM_TrainStep's default step (bf16, composited) on the ICT prior: the subject's dataset
// re-expressed in ICT-FaceKit with its cameras held (icef track --keep-cameras --face-model ict
// --landmarks model; `icef bench --face-model ict` trains on such datasets), warmed up the same way.
// Compare steps/s with BM_TrainStep/bf16:1/composited:1 of the same run: the ICT prior's cost per
// step (the warp's closest points, cached per expression on model/lazy_grid.h's grid).
void BM_TrainStepIct(benchmark::State& state) {
  const Subject& s = TrainedSubject();
  if (!s.error.empty()) return state.SkipWithError(s.error.c_str());
  if (!std::filesystem::exists(icef::face::IctModel::DefaultPath()))
    return state.SkipWithError("no ICT-FaceKit model installed");
  icef::track::RetrackOptions ro;
  ro.landmarks = icef::track::RetrackLandmarks::kDatasetModel;
  ro.face_model = icef::track::TrackFaceModel::kIct;
  const icef::Result<icef::track::RetrackResult> ict =
      icef::track::RetrackDataset(s.dataset, ro, icef::Executor(2));
  if (!ict.ok()) return state.SkipWithError(ict.status().message().c_str());
  icef::RunConfig config;
  config.train.steps = 1000000;
  config.train.threads = 2;
  config.train.checkpoint_every = 0;
  TimeTrainSteps(state, ict->dataset, config, true, "train_ict");
}
BENCHMARK(BM_TrainStepIct)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(3.0);

// The start of a run, which BM_TrainStep leaves out: a fresh trainer's first
// train.occupancy_warmup + 44 steps (the steps BM_TrainStep takes before it times), on 2 threads.
// While the field is still fog its rays stop late, so more of their samples run the colour MLP and
// the prior shading's normals: a change to that per-sample work shows here more than in
// BM_TrainStep. One iteration: a whole short training (docs/engine.md, "The start of a run").
void BM_TrainWarmup(benchmark::State& state) {
  const Subject& s = TrainedSubject();
  if (!s.error.empty()) return state.SkipWithError(s.error.c_str());
  icef::RunConfig config;
  config.train.steps = 1000000;
  config.train.threads = 2;
  config.train.checkpoint_every = 0;
  const int steps = config.train.occupancy_warmup + 44;
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("icef_warmup_bench_" + std::to_string(::getpid()));
  int64_t samples = 0;
  for (auto _ : state) {
    state.PauseTiming();
    auto trainer = icef::Trainer::Create(s.dataset, dir, config);
    if (!trainer.ok()) return state.SkipWithError(trainer.status().message().c_str());
    state.ResumeTiming();
    for (int i = 0; i < steps; ++i) {
      const icef::Result<icef::LossTerms> terms = (*trainer)->Step();
      if (!terms.ok()) return state.SkipWithError(terms.status().message().c_str());
      samples += terms->samples;
    }
    state.PauseTiming();
    trainer->reset();
    std::filesystem::remove_all(dir);
    state.ResumeTiming();
  }
  const double total = static_cast<double>(state.iterations()) * steps;
  state.counters["steps/s"] = benchmark::Counter(total, benchmark::Counter::kIsRate);
  state.counters["rays/s"] = benchmark::Counter(total * config.train.batch_rays, benchmark::Counter::kIsRate);
  state.counters["samples/s"] = benchmark::Counter(static_cast<double>(samples), benchmark::Counter::kIsRate);
  state.counters["samples/step"] = static_cast<double>(samples) / total;
}
BENCHMARK(BM_TrainWarmup)->Unit(benchmark::kSecond)->UseRealTime()->Iterations(1);

// icef eval's work per test frame (the far frame of the subject): its render and the model's
// neutral render of the same view, PSNR, SSIM, the expression-fidelity measures and, where the
// face-descriptor network is installed, the three face descriptors (the label says whether it
// was). LPIPS needs user-supplied weights and is left out.
void BM_EvalFrame(benchmark::State& state) {
  const Subject& s = TrainedSubject();
  if (!s.error.empty()) return state.SkipWithError(s.error.c_str());
  icef::Dataset one = s.dataset;
  one.test = {FarFrame(s)};
  const icef::Executor executor(2);
  icef::Result<icef::eval::FaceIdentity> identity =
      icef::eval::FaceIdentity::Load(icef::eval::FaceIdentityOptions{});
  icef::eval::EvalNetworks networks;
  if (identity.ok()) networks.identity = &*identity;
  icef::eval::EvalOptions options;  // no out_dir: nothing written
  for (auto _ : state) {
    const icef::Result<icef::eval::EvalResult> result =
        icef::eval::EvaluateModel(s.trainer->model(), one, options, networks, executor, nullptr);
    if (!result.ok()) return state.SkipWithError(result.status().message().c_str());
  }
  state.counters["frames/s"] =
      benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
  state.SetLabel(identity.ok() ? "with face descriptors"
                               : "without face descriptors (network not installed)");
}
BENCHMARK(BM_EvalFrame)->Unit(benchmark::kMillisecond)->UseRealTime();

// AvatarModel::RenderOccupancy alone: one density query per 2x2x2 cells through the warp.
void BM_RenderOccupancy(benchmark::State& state) {
  const Subject& s = TrainedSubject();
  if (!s.error.empty()) return state.SkipWithError(s.error.c_str());
  const icef::Frame& frame = FarFrame(s);
  const icef::Executor executor(2);
  for (auto _ : state)
    benchmark::DoNotOptimize(s.trainer->model().RenderOccupancy(frame.expression, executor));
}
BENCHMARK(BM_RenderOccupancy)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
