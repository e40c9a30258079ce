// The headline benchmarks on docs/design.md §7's reference configuration (see nn/reference_model.h):
// BM_ReferenceTrainStep (forward + backward + Adam over 4096 rays x 32 samples, 2 threads) and
// BM_ReferenceInference, each with a samples_per_second counter (wall clock); plus peak RSS and the fraction
// of the measured Eigen float32 GEMM rate (BM_GemmFp32) that the MLP work of the step reaches.
#include <benchmark/benchmark.h>
#include <sys/resource.h>

#include <cstdio>
#include <ctime>
#include <vector>

#include "icef/core/parallel.h"
#include "icef/nn/reference_model.h"

namespace icef::nn {

double MeasuredGemmFlops();  // nn_bench.cc
const ReferenceBatch& BenchBatch();
int BenchThreads();

namespace {

double ProcessCpuSeconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

double WallSeconds() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

// cpu_utilisation = process CPU time / (wall time x threads): 1.0 on an idle machine, lower when
// other processes take the cores (then samples_per_second understates the engine's speed and
// samples_per_cpu_second x threads is the better estimate).
void ReportCpu(benchmark::State& state, double samples, double cpu0, double wall0, int threads) {
  const double cpu = ProcessCpuSeconds() - cpu0, wall = WallSeconds() - wall0;
  state.counters["samples_per_cpu_second"] = samples / cpu;
  state.counters["cpu_utilisation"] = cpu / (wall * threads);
}

double PeakRssMb() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return u.ru_maxrss / 1024.0;  // Linux: kilobytes
}

ReferenceModel& Model() {
  static ReferenceModel model(1);
  return model;
}

// MLP FLOPs per sample of one training step: forward (2 per MAC), weight gradients (2 per MAC),
// input gradients (2 per MAC) except the deformation net's first layer, whose input needs none.
double TrainMlpFlopsPerSample(const ReferenceModel& m) {
  const MlpShape& d = m.deform().mlp().shape();
  return 6.0 * m.MlpMacsPerSample() - 2.0 * d.widths()[0] * d.widths()[1];
}

}  // namespace

static void BM_ReferenceTrainStep(benchmark::State& state) {
  ReferenceModel& m = Model();
  const ReferenceBatch& batch = BenchBatch();
  const Executor ex(BenchThreads());
  m.TrainStep(ex, batch);  // warm-up: buffers, page faults
  const ReferenceTimings before = m.timings();
  double loss = 0;
  const double cpu0 = ProcessCpuSeconds(), wall0 = WallSeconds();
  for (auto _ : state) loss = m.TrainStep(ex, batch);
  const double wall = WallSeconds() - wall0;
  const double samples = double(batch.num_samples()) * state.iterations();
  ReportCpu(state, samples, cpu0, wall0, ex.num_threads());
  state.counters["samples_per_second"] = samples / wall;
  state.counters["mlp_flops_per_second"] = TrainMlpFlopsPerSample(m) * samples / wall;
  const double gemm = MeasuredGemmFlops();
  // fraction_of_gemm is filled in as a plain value: MLP FLOP rate over the whole step / GEMM rate.
  ReferenceTimings t = m.timings();
  const double steps = double(t.steps - before.steps);
  const double step_s = (t.fused_tiles - before.fused_tiles + t.grid_scatter - before.grid_scatter +
                         t.reduce - before.reduce + t.adam - before.adam) / steps;
  const double rate = TrainMlpFlopsPerSample(m) * batch.num_samples() / step_s;
  state.counters["fraction_of_gemm"] = rate / gemm;
  // The FLOP floor: the samples/s the step's MLP FLOPs would allow at the measured GEMM rate. Its
  // fraction is the machine-independent figure (the absolute rate follows the GEMM rate, which
  // differs by 2x between machines of the same core count).
  const double floor = gemm / TrainMlpFlopsPerSample(m);
  state.counters["floor_samples_per_second"] = floor;
  state.counters["fraction_of_floor"] = (samples / wall) / floor;
  state.counters["gemm_flops_per_second"] = gemm;
  state.counters["peak_rss_mb"] = PeakRssMb();
  state.counters["loss"] = loss;
  state.counters["ms_fused_tiles"] = 1e3 * (t.fused_tiles - before.fused_tiles) / steps;
  state.counters["ms_grid_scatter"] = 1e3 * (t.grid_scatter - before.grid_scatter) / steps;
  state.counters["ms_reduce"] = 1e3 * (t.reduce - before.reduce) / steps;
  state.counters["ms_adam"] = 1e3 * (t.adam - before.adam) / steps;
  std::printf("BM_ReferenceTrainStep: %.3f M samples/s = %.1f%% of the %.2f M samples/s FLOP floor; MLPs at %.1f "
              "GFLOP/s = %.1f%% of the %.1f GFLOP/s Eigen GEMM; peak RSS %.0f MB; CPU utilisation %.0f%%\n",
              batch.num_samples() / step_s / 1e6, 100.0 * batch.num_samples() / step_s / floor, floor / 1e6,
              rate / 1e9, 100.0 * rate / gemm, gemm / 1e9, PeakRssMb(), 100.0 * state.counters["cpu_utilisation"]);
}
// No UseRealTime()/MinTime(): they would append "/real_time" etc. to the names that results.json
// is tracked by. The rate counters are computed from our own wall clock instead (the default
// iteration count follows the main thread's CPU time, at least 0.5 s of it).
BENCHMARK(BM_ReferenceTrainStep)->Unit(benchmark::kMillisecond);

static void BM_ReferenceInference(benchmark::State& state) {
  ReferenceModel& m = Model();
  const ReferenceBatch& batch = BenchBatch();
  const Executor ex(BenchThreads());
  std::vector<float> out(batch.num_samples() * 4);
  m.Infer(ex, batch, out.data());
  const double cpu0 = ProcessCpuSeconds(), wall0 = WallSeconds();
  for (auto _ : state) {
    m.Infer(ex, batch, out.data());
    benchmark::DoNotOptimize(out.data());
  }
  const double wall = WallSeconds() - wall0;
  const double samples = double(batch.num_samples()) * state.iterations();
  ReportCpu(state, samples, cpu0, wall0, ex.num_threads());
  state.counters["samples_per_second"] = samples / wall;
  state.counters["mlp_flops_per_second"] = 2.0 * m.MlpMacsPerSample() * samples / wall;
  state.counters["peak_rss_mb"] = PeakRssMb();
  const double floor = MeasuredGemmFlops() / (2.0 * m.MlpMacsPerSample());
  state.counters["floor_samples_per_second"] = floor;
  state.counters["fraction_of_floor"] = (samples / wall) / floor;
  std::printf("BM_ReferenceInference: %.3f M samples/s = %.1f%% of the %.2f M samples/s FLOP floor\n",
              samples / wall / 1e6, 100.0 * samples / wall / floor, floor / 1e6);
}
BENCHMARK(BM_ReferenceInference)->Unit(benchmark::kMillisecond);

}  // namespace icef::nn
