// MediaPipe's face mesh run by infer's TF.js graph runner, as icef track runs it twice per photo
// (one 192 x 192 crop per pass), on one thread; fraction_of_gemm = its convolutions' FLOP rate
// over the machine's measured float32 GEMM rate (nn_bench.cc's MeasuredGemmFlops: 2 threads).
// Skipped when install-deps.sh has not installed the model.
#include <benchmark/benchmark.h>

#include <Eigen/Core>
#include <cmath>
#include <filesystem>

#include "icef/infer/tfjs_graph.h"

namespace icef::nn {
double MeasuredGemmFlops();  // nn_bench.cc
}  // namespace icef::nn

namespace {

void BM_FaceMeshGraph(benchmark::State& state) {
  const std::filesystem::path model = "/usr/local/share/icef/facemesh/facemesh.json";
  auto graph = icef::infer::TfjsGraph::Load(model);
  if (!graph.ok()) {
    state.SkipWithError(graph.status().message().c_str());
    return;
  }
  icef::infer::Tensor3 crop(192, 192, 3);
  for (int y = 0; y < 192; ++y)
    for (int x = 0; x < 192; ++x)
      for (int c = 0; c < 3; ++c) crop.At(y, x, c) = 0.5f + 0.4f * std::sin(0.05f * x * (c + 1) + 0.07f * y);
  // The GEMM rate first: measuring it sets Eigen to 2 threads, and the graph's small products run
  // on one (as icef track runs them; several threads would spin on them).
  const double gemm = icef::nn::MeasuredGemmFlops();
  Eigen::setNbThreads(1);
  double flops = 0;
  for (auto _ : state) {
    auto out = graph->Run(crop, {"output_mesh", "output_faceflag"}, &flops);
    benchmark::DoNotOptimize(out);
  }
  const double rate = static_cast<double>(state.iterations()) * flops;
  state.counters["crops/s"] =
      benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
  state.counters["GFLOP/crop"] = flops / 1e9;
  state.counters["fraction_of_gemm"] = benchmark::Counter(rate / gemm, benchmark::Counter::kIsRate);
}
BENCHMARK(BM_FaceMeshGraph)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
