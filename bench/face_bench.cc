// The face model's per-point costs, which the prior-guided methods pay per sample: the signed
// distance, the prior warp and the surface normal (four distances), at points around the face of the
// average head, neutral and with a moderate expression, on one thread; and the neutral normals in
// one vectorised batch.
#include <benchmark/benchmark.h>

#include <vector>

#include "icef/core/rng.h"
#include "icef/face/expression.h"
#include "icef/face/face_model.h"

namespace {

using icef::Vec3f;
namespace face = icef::face;

std::vector<Vec3f> FacePoints(int n) {
  icef::Rng rng(7, 0);
  std::vector<Vec3f> points(n);
  // The front half of the head box, where the expression regions and most rendered samples lie.
  for (Vec3f& p : points)
    p = Vec3f(static_cast<float>(rng.Uniform(-0.3, 0.3)), static_cast<float>(rng.Uniform(-0.35, 0.3)),
              static_cast<float>(rng.Uniform(0.0, 0.4)));
  return points;
}

face::ExpressionState State(const face::FaceModel& model, int which) {
  std::vector<float> beta(face::kNumExpressions, 0.f);
  if (which == 1)
    beta[face::kJawOpen] = 0.5f, beta[face::kSmileLeft] = 0.4f, beta[face::kBrowRaiseRight] = 0.3f;
  return model.Prepare(beta);
}

// Arg: expression (0 neutral, 1 moderate). `kind` picks the call.
template <int kind>
void BM_FaceModelPoint(benchmark::State& state) {
  const face::FaceModel model{face::ShapeParams()};
  const face::ExpressionState s = State(model, static_cast<int>(state.range(0)));
  const std::vector<Vec3f> points = FacePoints(4096);
  for (auto _ : state) {
    for (const Vec3f& p : points) {
      if constexpr (kind == 0) benchmark::DoNotOptimize(model.Distance(p, s));
      if constexpr (kind == 1) benchmark::DoNotOptimize(model.PriorWarp(p, s));
      if constexpr (kind == 2) benchmark::DoNotOptimize(model.Normal(p, s));
    }
  }
  state.counters["points/s"] = benchmark::Counter(static_cast<double>(state.iterations()) * points.size(),
                                                  benchmark::Counter::kIsRate);
}
// The neutral surface's normals at many canonical points at once (the vectorised batch the prior's
// shading uses), against BM_FaceModelNormal's one point at a time.
void BM_FaceModelCanonicalNormals(benchmark::State& state) {
  const face::FaceModel model{face::ShapeParams()};
  const face::ExpressionState s = State(model, 0);
  const std::vector<Vec3f> points = FacePoints(4096);
  std::vector<Vec3f> normals(points.size());
  for (auto _ : state) {
    model.CanonicalNormals(points, s, normals.data());
    benchmark::DoNotOptimize(normals.data());
  }
  state.counters["points/s"] = benchmark::Counter(static_cast<double>(state.iterations()) * points.size(),
                                                  benchmark::Counter::kIsRate);
}
BENCHMARK(BM_FaceModelCanonicalNormals)->UseRealTime();

BENCHMARK(BM_FaceModelPoint<0>)->Name("BM_FaceModelDistance")->ArgName("expr")->Arg(0)->Arg(1)->UseRealTime();
BENCHMARK(BM_FaceModelPoint<1>)
    ->Name("BM_FaceModelPriorWarp")
    ->ArgName("expr")
    ->Arg(0)
    ->Arg(1)
    ->UseRealTime();
BENCHMARK(BM_FaceModelPoint<2>)->Name("BM_FaceModelNormal")->ArgName("expr")->Arg(0)->Arg(1)->UseRealTime();

}  // namespace
