// Ground-truth renderer throughput: one 128x128 frame (2x2 supersampling) of the procedural head,
// neutral and with a moderate and a far expression, on 1 and 2 threads; plus a whole tiny dataset.
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <filesystem>

#include "icef/face/expression.h"
#include "icef/synth/ground_truth_renderer.h"
#include "icef/synth/synthesize.h"

namespace {

using icef::face::kNumExpressions;

std::vector<float> Expression(int which) {
  std::vector<float> beta(kNumExpressions, 0.f);
  if (which == 1)
    beta[icef::face::kJawOpen] = 0.5f, beta[icef::face::kSmileLeft] = 0.4f,
    beta[icef::face::kBrowRaiseRight] = 0.3f;
  if (which == 2)
    for (int e :
         {icef::face::kJawOpen, icef::face::kSmileLeft, icef::face::kEyeCloseLeft, icef::face::kCheekPuff})
      beta[e] = 1.5f;
  return beta;
}

// Args: threads, expression (0 neutral, 1 moderate, 2 far).
void BM_SynthRenderFrame128(benchmark::State& state) {
  const icef::synth::HeadModel head(icef::synth::IdentityParams::FromSeed(1));
  icef::Intrinsics in;
  in.width = in.height = 128;
  in.fl_x = in.fl_y = 3.6 * 128;
  in.cx = in.cy = 64;
  const icef::Camera camera = icef::synth::OrbitCamera(in, 3.5, 20.0, 5.0);
  const icef::Executor executor(static_cast<int>(state.range(0)));
  const std::vector<float> beta = Expression(static_cast<int>(state.range(1)));
  for (auto _ : state) benchmark::DoNotOptimize(icef::synth::RenderGroundTruth(head, camera, beta, executor));
  state.counters["frames/s"] =
      benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
  state.counters["rays/s"] = benchmark::Counter(static_cast<double>(state.iterations()) * 128 * 128 * 4,
                                                benchmark::Counter::kIsRate);
}
BENCHMARK(BM_SynthRenderFrame128)
    ->ArgNames({"threads", "expr"})
    ->Args({1, 0})
    ->Args({2, 0})
    ->Args({2, 1})
    ->Args({2, 2})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// A K=5, V=3, 128x128 dataset (41 images + landmarks + JSON) on 2 threads.
void BM_SynthDataset(benchmark::State& state) {
  icef::synth::SynthOptions options;
  options.out_dir =
      std::filesystem::temp_directory_path() / ("icef_synth_bench_" + std::to_string(::getpid()));
  const icef::Executor executor(2);
  for (auto _ : state) {
    const icef::Status status = icef::synth::SynthesizeDataset(options, executor);
    if (!status.ok()) state.SkipWithError(status.message().c_str());
  }
  std::filesystem::remove_all(options.out_dir);
}
BENCHMARK(BM_SynthDataset)->Unit(benchmark::kSecond)->UseRealTime()->Iterations(1);

}  // namespace
