// Benchmarks of the nn building blocks on docs/design.md §7's reference configuration (4096 rays x 32
// samples, 2 threads): hash encoding, each MLP, and the Eigen float32 GEMM rate that the MLP
// figures are compared with (counter fraction_of_gemm = MLP FLOP rate / GEMM FLOP rate).
#include <benchmark/benchmark.h>

// GCC 12 reports false -Wmaybe-uninitialized positives inside Eigen's AVX-512 GEMM kernels.
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#include <Eigen/Core>
#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <vector>

#include "icef/core/parallel.h"
#include "icef/core/rng.h"
#include "icef/math/ray.h"
#include "icef/nn/gemm.h"
#include "icef/nn/hash_grid.h"
#include "icef/nn/mlp.h"

namespace icef::nn {

// Threads of every benchmark: 2 (docs/design.md §7), or ICEF_BENCH_THREADS (e.g. 1 to read per-core
// CPU time on a busy machine).
int BenchThreads() {
  static const int threads = [] {
    const char* env = std::getenv("ICEF_BENCH_THREADS");
    return env ? std::max(1, std::atoi(env)) : 2;
  }();
  return threads;
}
constexpr int64_t kRays = 4096;
constexpr int kSamplesPerRay = 32;

// Measures the Eigen float32 2048x2048 matrix-multiply rate once (FLOP/s, 2 threads), so that every
// MLP figure can be expressed as a fraction of it.
double MeasuredGemmFlops() {
  static const double rate = [] {
    const int n = 2048;
    Eigen::setNbThreads(BenchThreads());
    Eigen::MatrixXf a = Eigen::MatrixXf::Random(n, n), b = Eigen::MatrixXf::Random(n, n), c(n, n);
    c.noalias() = a * b;  // warm-up
    double best = 0;
    for (int rep = 0; rep < 5; ++rep) {
      const auto t0 = std::chrono::steady_clock::now();
      c.noalias() = a * b;
      const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      best = std::max(best, 2.0 * n * n * n / s);
    }
    benchmark::DoNotOptimize(c.data());
    return best;
  }();
  return rate;
}

// The samples of every benchmark: kRays rays from a sphere of radius 3 through the box [-1,1]^3,
// kSamplesPerRay evenly spaced inside it, as normalised positions in [0,1]^3 [n, 3] (ray-coherent,
// as a training batch's samples are: the hash grid's cache behaviour depends on it). The draws are
// those of the retired reference model's batch, so that the figures stay comparable with earlier runs.
static int64_t BenchSamples() { return kRays * kSamplesPerRay; }
static const std::vector<float>& BenchPositions() {
  static const std::vector<float> positions = [] {
    std::vector<float> p(BenchSamples() * 3);
    const Aabb box;
    for (int64_t r = 0; r < kRays; ++r) {
      Rng rng(1, StreamId("reference_batch"), 0, static_cast<uint64_t>(r));
      Vec3f o(static_cast<float>(rng.Normal()), static_cast<float>(rng.Normal()),
              static_cast<float>(rng.Normal()));
      o = 3.0f * o.normalized();
      const Vec3f target(rng.Uniform(-0.3, 0.3), rng.Uniform(-0.3, 0.3), rng.Uniform(-0.3, 0.3));
      const Ray ray{o, (target - o).normalized()};
      const Interval iv = box.Intersect(ray).value_or(Interval{2.0f, 4.0f});
      for (int k = 0; k < kSamplesPerRay; ++k) {
        const float t = iv.t_near + (k + 0.5f) / kSamplesPerRay * (iv.t_far - iv.t_near);
        const Vec3f x = ray.At(t).cwiseMax(-1.0f).cwiseMin(1.0f);
        for (int a = 0; a < 3; ++a) p[3 * (r * kSamplesPerRay + k) + a] = 0.5f * (x[a] + 1.0f);
      }
    }
    return p;
  }();
  return positions;
}

static void BM_GemmFp32(benchmark::State& state) {
  const int n = 2048;
  Eigen::setNbThreads(BenchThreads());
  Eigen::MatrixXf a = Eigen::MatrixXf::Random(n, n), b = Eigen::MatrixXf::Random(n, n), c(n, n);
  const auto t0 = std::chrono::steady_clock::now();
  for (auto _ : state) {
    c.noalias() = a * b;
    benchmark::DoNotOptimize(c.data());
    benchmark::ClobberMemory();
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  state.counters["flops_per_second"] = 2.0 * n * n * n * state.iterations() / seconds;  // wall clock
  state.SetLabel(std::string("Eigen ") + std::to_string(EIGEN_WORLD_VERSION) + "." +
                 std::to_string(EIGEN_MAJOR_VERSION) + "." + std::to_string(EIGEN_MINOR_VERSION) + ", SIMD " +
                 Eigen::SimdInstructionSetsInUse() + "; nn kernel " + GemmKernelName());
}
// Plain name (tracked in results.json); the counter uses the wall clock.
BENCHMARK(BM_GemmFp32)->Unit(benchmark::kMillisecond);

// ---- Hash encoding -------------------------------------------------------------------------

struct GridFixture {
  ParameterStore store;
  HashGridEncoding grid{ReferenceHashGridOptions(), &store, "grid"};
  std::vector<float> pos, feat, jac, dfeat, dpos;
  GridFixture() {
    grid.Initialize(1);
    const int64_t n = BenchSamples();
    pos = BenchPositions();
    feat.resize(n * 32);
    jac.resize(n * 96);
    dfeat.assign(n * 32, 1e-3f);
    dpos.resize(n * 3);
  }
};
GridFixture& Grid() {
  static GridFixture f;
  return f;
}

static void BM_HashGridForward(benchmark::State& state) {
  GridFixture& f = Grid();
  const Executor ex(BenchThreads());
  const int64_t n = BenchSamples();
  for (auto _ : state) f.grid.Forward(ex, n, f.pos.data(), f.feat.data(), nullptr);
  state.counters["samples_per_second"] =
      benchmark::Counter(double(n) * state.iterations(), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_HashGridForward)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(1.0);

static void BM_HashGridForwardBackward(benchmark::State& state) {
  GridFixture& f = Grid();
  const Executor ex(BenchThreads());
  const int64_t n = BenchSamples();
  for (auto _ : state) {
    f.grid.Forward(ex, n, f.pos.data(), f.feat.data(), f.jac.data());
    f.grid.BackwardInput(ex, n, f.jac.data(), f.dfeat.data(), f.dpos.data());
    f.grid.BackwardParams(ex, n, f.pos.data(), f.dfeat.data());
  }
  state.counters["samples_per_second"] =
      benchmark::Counter(double(n) * state.iterations(), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_HashGridForwardBackward)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(1.0);

// ---- MLPs ----------------------------------------------------------------------------------

MlpOptions BenchMlpOptions(int which) {
  MlpOptions o;
  if (which == 0) {
    o.widths = {55, 64, 64, 64, 3};  // deformation
  } else if (which == 1) {
    o.widths = {32, 64, 16};  // density
  } else {
    o.widths = {32, 64, 64, 3};  // colour
    o.output_activation = Activation::kSigmoid;
  }
  return o;
}
const char* kMlpNames[] = {"deform_55-64-64-64-3", "density_32-64-16", "colour_32-64-64-3"};

// Adds fraction_of_gemm = (flops / seconds of the timed loop) / MeasuredGemmFlops().
void ReportGemmFraction(benchmark::State& state, double flops, double seconds);

static void BM_MlpForward(benchmark::State& state) {
  const int which = static_cast<int>(state.range(0));
  ParameterStore store;
  Mlp mlp(BenchMlpOptions(which), &store, "mlp");
  mlp.Initialize(1);
  const int64_t n = BenchSamples();
  std::vector<float> x(n * mlp.input_dims(), 0.3f), y(n * mlp.output_dims());
  for (size_t i = 0; i < x.size(); ++i) x[i] = float(int(i % 17) - 8) / 8.0f;
  const Executor ex(BenchThreads());
  MlpContext ctx;
  const auto t0 = std::chrono::steady_clock::now();
  for (auto _ : state) mlp.Forward(ex, n, x.data(), y.data(), &ctx, /*keep_for_backward=*/false);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const double flops = 2.0 * mlp.num_params() * n * state.iterations();
  state.counters["samples_per_second"] =
      benchmark::Counter(double(n) * state.iterations(), benchmark::Counter::kIsRate);
  state.counters["flops_per_second"] = benchmark::Counter(flops, benchmark::Counter::kIsRate);
  ReportGemmFraction(state, flops, seconds);
  state.SetLabel(kMlpNames[which]);
}
BENCHMARK(BM_MlpForward)->DenseRange(0, 2)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(0.5);

static void BM_MlpForwardBackward(benchmark::State& state) {
  const int which = static_cast<int>(state.range(0));
  ParameterStore store;
  Mlp mlp(BenchMlpOptions(which), &store, "mlp");
  mlp.Initialize(1);
  const int64_t n = BenchSamples();
  std::vector<float> x(n * mlp.input_dims()), y(n * mlp.output_dims()), dy(n * mlp.output_dims(), 1e-3f),
      dx(n * mlp.input_dims());
  for (size_t i = 0; i < x.size(); ++i) x[i] = float(int(i % 17) - 8) / 8.0f;
  const Executor ex(BenchThreads());
  MlpContext ctx;
  const auto t0 = std::chrono::steady_clock::now();
  for (auto _ : state) {
    mlp.Forward(ex, n, x.data(), y.data(), &ctx);
    mlp.Backward(ex, n, x.data(), y.data(), dy.data(), &ctx, dx.data());
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const double flops = 6.0 * mlp.num_params() * n * state.iterations();
  state.counters["samples_per_second"] =
      benchmark::Counter(double(n) * state.iterations(), benchmark::Counter::kIsRate);
  state.counters["flops_per_second"] = benchmark::Counter(flops, benchmark::Counter::kIsRate);
  ReportGemmFraction(state, flops, seconds);
  state.SetLabel(kMlpNames[which]);
}
BENCHMARK(BM_MlpForwardBackward)
    ->DenseRange(0, 2)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MinTime(0.5);

void ReportGemmFraction(benchmark::State& state, double flops, double seconds) {
  if (seconds > 0) state.counters["fraction_of_gemm"] = flops / seconds / MeasuredGemmFlops();
}

}  // namespace icef::nn
