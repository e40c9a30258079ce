#include "icef/field/static_field.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "icef/core/rng.h"
#include "icef/nn/sh_encoding.h"

namespace icef {

namespace {
nn::MlpOptions DensityMlpOptions(const StaticFieldOptions& o, int grid_dims) {
  nn::MlpOptions m;
  m.widths = {grid_dims + o.condition_dims, o.density_hidden, o.geo_features};
  m.output_activation = nn::Activation::kNone;
  m.bf16_inference = o.bf16_inference;
  m.bf16_training = o.bf16_training;
  return m;
}
nn::MlpOptions ColorMlpOptions(const StaticFieldOptions& o) {
  nn::MlpOptions m;
  m.widths = {o.geo_features + o.sh_degree * o.sh_degree};
  for (int w : o.color_hidden) m.widths.push_back(w);
  m.widths.push_back(3);
  m.output_activation = nn::Activation::kSigmoid;
  m.bf16_inference = o.bf16_inference;
  m.bf16_training = o.bf16_training;
  return m;
}
}  // namespace

Status StaticFieldOptions::Validate() const {
  ICEF_RETURN_IF_ERROR(grid.Validate().WithContext("grid"));
  if (density_hidden < 1) return Status::Error("density_hidden must be >= 1");
  if (geo_features < 1) return Status::Error("geo_features must be >= 1");
  for (int w : color_hidden)
    if (w < 1) return Status::Error("color_hidden widths must be >= 1");
  if (sh_degree < 1 || sh_degree > 4) return Status::Error("sh_degree must be in [1, 4]");
  if (condition_dims < 0) return Status::Error("condition_dims must be >= 0");
  if (!std::isfinite(density_bias)) return Status::Error("density_bias must be finite");
  return Status::Ok();
}

std::string StaticFieldOptions::ToString() const {
  std::ostringstream os;
  os << "StaticFieldOptions(grid=" << grid.ToString() << ", density_hidden=" << density_hidden
     << ", geo_features=" << geo_features << ", color_hidden=" << color_hidden.size() << "x"
     << (color_hidden.empty() ? 0 : color_hidden[0]) << ", sh_degree=" << sh_degree
     << ", condition_dims=" << condition_dims << ")";
  return os.str();
}

StaticField::StaticField(const StaticFieldOptions& options, const Aabb& aabb, nn::ParameterStore* store,
                         const std::string& name, int grid_group, int mlp_group)
    : options_(options),
      aabb_(aabb),
      grid_(options.grid, store, name + "/grid", grid_group),
      density_mlp_(DensityMlpOptions(options, grid_.output_dims()), store, name + "/density", mlp_group),
      color_mlp_(ColorMlpOptions(options), store, name + "/color", mlp_group) {
  ICEF_CHECK(options.Validate().ok(), options.Validate().message());
  ICEF_CHECK(aabb.IsValid(), aabb.ToString());
}

void StaticField::Initialize(uint64_t seed) {
  grid_.Initialize(Mix64(seed ^ 1));
  density_mlp_.Initialize(Mix64(seed ^ 2));
  color_mlp_.Initialize(Mix64(seed ^ 3));
}

void StaticField::SetLevelWeights(std::vector<float> weights) {
  ICEF_CHECK(weights.empty() || int(weights.size()) == options_.grid.num_levels, "one weight per grid level");
  bool all_one = true;
  for (float w : weights) all_one &= (w == 1.f);
  level_weights_ = all_one ? std::vector<float>() : std::move(weights);
}

void StaticField::ScaleLevels(int64_t n, float* features) const {
  if (level_weights_.empty()) return;
  const int levels = options_.grid.num_levels, f = options_.grid.features_per_level, g = levels * f;
  for (int64_t i = 0; i < n; ++i)
    for (int l = 0; l < levels; ++l)
      for (int k = 0; k < f; ++k) features[i * g + l * f + k] *= level_weights_[l];
}

void StaticField::DensityForward(const Executor& executor, int64_t n, const float* positions,
                                 const float* condition, StaticFieldContext* ctx, bool keep_for_backward,
                                 bool need_position_grad) const {
  const int g = grid_.output_dims(), c = options_.condition_dims, di = g + c;
  ctx->n = n;
  ctx->has_position_jacobian = need_position_grad;
  nn::GrowTo(ctx->unit_positions, n * 3);
  nn::GrowTo(ctx->density_input, n * di);
  nn::GrowTo(ctx->density_output, n * options_.geo_features);
  if (need_position_grad) nn::GrowTo(ctx->grid_jacobian, n * g * 3);
  const Vec3f lo = aabb_.min, inv = aabb_.Extent().cwiseInverse();
  float* unit = ctx->unit_positions.data();
  ParallelFor(executor, n, [&](int64_t b, int64_t e, int) {
    for (int64_t i = b; i < e; ++i)
      for (int a = 0; a < 3; ++a) unit[3 * i + a] = (positions[3 * i + a] - lo[a]) * inv[a];
  });
  // The grid writes [n, g]; with a condition the rows are widened to [n, g + c] afterwards.
  if (c != 0) nn::GrowTo(ctx->grid_features, n * g);
  float* features = c == 0 ? ctx->density_input.data() : ctx->grid_features.data();
  grid_.Forward(executor, n, unit, features, need_position_grad ? ctx->grid_jacobian.data() : nullptr);
  ScaleLevels(n, features);  // the Jacobian stays unscaled: Backward scales the incoming gradient
  if (c != 0) {
    float* in = ctx->density_input.data();
    ParallelFor(executor, n, [&](int64_t b, int64_t e, int) {
      for (int64_t i = b; i < e; ++i) {
        std::copy(features + i * g, features + (i + 1) * g, in + i * di);
        std::copy(condition + i * c, condition + (i + 1) * c, in + i * di + g);
      }
    });
  }
  density_mlp_.Forward(executor, n, ctx->density_input.data(), ctx->density_output.data(), &ctx->density_mlp,
                       keep_for_backward);
}

void StaticField::ForwardDensity(const Executor& executor, int64_t n, const float* positions,
                                 const float* condition, float* sigma, StaticFieldContext* ctx,
                                 bool keep_for_backward, bool need_position_grad) const {
  DensityForward(executor, n, positions, condition, ctx, keep_for_backward, need_position_grad);
  const int geo = options_.geo_features;
  const float* h = ctx->density_output.data();
  ParallelFor(executor, n, [&](int64_t b, int64_t e, int) {
    for (int64_t i = b; i < e; ++i)
      sigma[i] = std::exp(std::min(h[i * geo] + options_.density_bias, kMaxLogDensity));
  });
}

void StaticField::ForwardColor(const Executor& executor, int64_t n, const float* directions,
                               std::optional<std::span<const int32_t>> rows, float* rgb,
                               StaticFieldContext* ctx, bool keep_for_backward) const {
  ctx->color_all = !rows.has_value();
  const int64_t m = rows ? static_cast<int64_t>(rows->size()) : n;
  if (rows) {
    ctx->color_rows.assign(rows->begin(), rows->end());
    for (int64_t j = 0; j < m; ++j)
      ICEF_CHECK(ctx->color_rows[j] >= 0 && ctx->color_rows[j] < n &&
                     (j == 0 || ctx->color_rows[j] > ctx->color_rows[j - 1]),
                 "StaticField::ForwardColor: rows must ascend within [0, n)");
  }
  const int geo = options_.geo_features, sh = options_.sh_degree * options_.sh_degree, ci = geo + sh;
  nn::GrowTo(ctx->color_input, m * ci);
  float* cin = ctx->color_input.data();
  const float* h = ctx->density_output.data();
  const int32_t* index = ctx->color_rows.data();
  const bool all = ctx->color_all;
  ParallelFor(executor, m, [&](int64_t b, int64_t e, int) {
    for (int64_t j = b; j < e; ++j) {
      const int64_t i = all ? j : index[j];
      std::copy(h + i * geo, h + (i + 1) * geo, cin + j * ci);
      nn::ShForward<float>(options_.sh_degree, 1, directions + 3 * i, cin + j * ci + geo);
    }
  });
  if (all) {
    color_mlp_.Forward(executor, n, cin, rgb, &ctx->color_mlp, keep_for_backward);
    return;
  }
  nn::GrowTo(ctx->color_output, m * 3);
  color_mlp_.Forward(executor, m, cin, ctx->color_output.data(), &ctx->color_mlp, keep_for_backward);
  std::fill(rgb, rgb + 3 * n, 0.f);
  for (int64_t j = 0; j < m; ++j)
    for (int a = 0; a < 3; ++a) rgb[3 * index[j] + a] = ctx->color_output[3 * j + a];
}

void StaticField::Forward(const Executor& executor, int64_t n, const float* positions,
                          const float* directions, const float* condition, float* sigma, float* rgb,
                          StaticFieldContext* ctx, bool keep_for_backward, bool need_position_grad) const {
  ForwardDensity(executor, n, positions, condition, sigma, ctx, keep_for_backward, need_position_grad);
  ForwardColor(executor, n, directions, std::nullopt, rgb, ctx, keep_for_backward);
}

void StaticField::Backward(const Executor& executor, int64_t n, const float* sigma, const float* rgb,
                           const float* d_sigma, const float* d_rgb, StaticFieldContext* ctx,
                           float* d_positions) {
  ICEF_CHECK(ctx->n == n, "Backward batch size differs from Forward");
  ICEF_CHECK(d_positions == nullptr || ctx->has_position_jacobian,
             "Forward was run without need_position_grad");
  const int g = grid_.output_dims(), c = options_.condition_dims, di = g + c;
  const int geo = options_.geo_features, sh = options_.sh_degree * options_.sh_degree, ci = geo + sh;
  const bool all = ctx->color_all;
  const int64_t m = all ? n : static_cast<int64_t>(ctx->color_rows.size());
  const int32_t* index = ctx->color_rows.data();
  nn::GrowTo(ctx->d_color_input, m * ci);
  nn::GrowTo(ctx->d_density_output, n * geo);
  nn::GrowTo(ctx->d_density_input, n * di);
  if (all) {
    color_mlp_.Backward(executor, n, ctx->color_input.data(), rgb, d_rgb, &ctx->color_mlp,
                        ctx->d_color_input.data());
  } else {  // the coloured rows' gradients, gathered as ForwardColor packed them
    nn::GrowTo(ctx->d_color_output, m * 3);
    for (int64_t j = 0; j < m; ++j)
      for (int a = 0; a < 3; ++a) ctx->d_color_output[3 * j + a] = d_rgb[3 * index[j] + a];
    color_mlp_.Backward(executor, m, ctx->color_input.data(), ctx->color_output.data(),
                        ctx->d_color_output.data(), &ctx->color_mlp, ctx->d_color_input.data());
  }
  const float* dci = ctx->d_color_input.data();
  const float* h = ctx->density_output.data();
  float* dh = ctx->d_density_output.data();
  if (!all) {
    std::fill(dh, dh + n * geo, 0.f);
    for (int64_t j = 0; j < m; ++j) std::copy(dci + j * ci, dci + j * ci + geo, dh + index[j] * geo);
  }
  ParallelFor(executor, n, [&](int64_t b, int64_t e, int) {
    for (int64_t i = b; i < e; ++i) {
      if (all) std::copy(dci + i * ci, dci + i * ci + geo, dh + i * geo);
      // sigma = exp(min(h0 + bias, max)): d sigma / d h0 = sigma below the clamp, 0 above.
      if (h[i * geo] + options_.density_bias < kMaxLogDensity) dh[i * geo] += d_sigma[i] * sigma[i];
    }
  });
  density_mlp_.Backward(executor, n, ctx->density_input.data(), ctx->density_output.data(), dh,
                        &ctx->density_mlp, ctx->d_density_input.data());
  // Grid gradients want [n, g]: compact the rows in place when a condition widened them.
  float* d_features = ctx->d_density_input.data();
  if (c != 0) {
    for (int64_t i = 0; i < n; ++i)
      std::copy(d_features + i * di, d_features + i * di + g, d_features + i * g);
  }
  ScaleLevels(n, d_features);  // d(w f)/d(theta, x) = w df/d(theta, x)
  grid_.BackwardParams(executor, n, ctx->unit_positions.data(), d_features);
  if (d_positions) {
    nn::GrowTo(ctx->d_unit_positions, n * 3);
    grid_.BackwardInput(executor, n, ctx->grid_jacobian.data(), d_features, ctx->d_unit_positions.data());
    const Vec3f inv = aabb_.Extent().cwiseInverse();
    const float* du = ctx->d_unit_positions.data();
    for (int64_t i = 0; i < n; ++i)
      for (int a = 0; a < 3; ++a) d_positions[3 * i + a] = du[3 * i + a] * inv[a];
  }
}

void StaticField::Density(const Executor& executor, int64_t n, const float* positions, const float* condition,
                          float* sigma, StaticFieldContext* ctx) const {
  DensityForward(executor, n, positions, condition, ctx, false, false);
  const int geo = options_.geo_features;
  const float* h = ctx->density_output.data();
  for (int64_t i = 0; i < n; ++i)
    sigma[i] = std::exp(std::min(h[i * geo] + options_.density_bias, kMaxLogDensity));
}

std::string StaticField::ToString() const {
  return "StaticField(" + options_.ToString() + ", aabb=" + aabb_.ToString() + ")";
}

}  // namespace icef
