#include "icef/train/density_start.h"

#include <cmath>
#include <vector>

#include "icef/core/rng.h"
#include "icef/face/face_model.h"
#include "icef/nn/adam.h"

namespace icef {

void DensityStartTargets(const face::FaceFit& fit, float density_bias, const DensityStartOptions& options,
                         int64_t count, const float* positions, float* targets, const Executor& executor) {
  const face::FaceModel head(fit.shape, fit.style);
  const face::ExpressionState neutral = head.Prepare(std::vector<float>(face::kNumExpressions, 0.f));
  auto step = [&](float v) { return 1.f / (1.f + std::exp(-v / options.width)); };  // sigmoid(v / width)
  ParallelFor(executor, count, [&](int64_t i0, int64_t i1, int) {
    for (int64_t i = i0; i < i1; ++i) {
      const Vec3d x(positions[3 * i], positions[3 * i + 1], positions[3 * i + 2]);
      const Vec3f x_head = fit.head_from_world.Apply(x).cast<float>();
      const float d = head.Distance(x_head, neutral) + options.erosion;
      const float inside = step(-d);
      targets[i] = density_bias + (options.inside_log_density - density_bias) * inside;
    }
  });
}

Result<double> SeedDensityFromFaceModel(const face::FaceFit& fit, const DensityStartOptions& options,
                                        uint64_t seed, AvatarModel* model, const Executor& executor) {
  if (options.steps < 0 || options.points < 1 || !(options.width > 0.f) || !(options.erosion >= 0.f) ||
      !std::isfinite(options.inside_log_density))
    return Status::Error(
        "density start: steps must be >= 0, points >= 1, width > 0, erosion >= 0, inside_log_density finite");
  StaticField& field = model->static_field();
  nn::ParameterStore& store = model->store();
  nn::AdamOptions adam_options;
  adam_options.groups.assign(3, nn::AdamGroup{});
  adam_options.groups[kGridGroup].learning_rate = options.learning_rate_grid;
  adam_options.groups[kGridGroup].sparse = true;
  adam_options.groups[kMlpGroup].learning_rate = options.learning_rate_mlp;
  nn::Adam adam(adam_options, &store);

  const int64_t n = options.points;
  const Aabb& aabb = field.aabb();
  const float bias = field.options().density_bias;
  const size_t count = static_cast<size_t>(n);
  std::vector<float> positions(3 * count), directions(3 * count, 0.f), targets(count);
  std::vector<float> sigma(count), rgb(3 * count), d_sigma(count), d_rgb(3 * count, 0.f);
  for (int64_t i = 0; i < n; ++i) directions[size_t(3 * i + 2)] = 1.f;
  StaticFieldContext ctx;
  double mse = 0;
  store.ZeroGrads();
  for (int step = 0; step < options.steps; ++step) {
    ParallelFor(executor, n, [&](int64_t i0, int64_t i1, int) {
      for (int64_t i = i0; i < i1; ++i) {
        Rng rng(seed, StreamId("density_start"), uint64_t(step), uint64_t(i));
        for (int a = 0; a < 3; ++a)
          positions[size_t(3 * i + a)] = aabb.min[a] + rng.Uniform() * (aabb.max[a] - aabb.min[a]);
      }
    });
    DensityStartTargets(fit, bias, options, n, positions.data(), targets.data(), executor);
    field.Forward(executor, n, positions.data(), directions.data(), nullptr, sigma.data(), rgb.data(), &ctx,
                  /*keep_for_backward=*/true, /*need_position_grad=*/false);
    mse = LogDensityLoss<float>(n, sigma.data(), targets.data(), d_sigma.data());
    field.Backward(executor, n, sigma.data(), rgb.data(), d_sigma.data(), d_rgb.data(), &ctx, nullptr);
    adam.Step(executor);
  }
  store.ZeroGrads();
  return mse;
}

}  // namespace icef
