#include "icef/field/deformation_field.h"

#include <cmath>
#include <sstream>

#include "icef/core/rng.h"

namespace icef {

namespace {
nn::FrequencyMlpOptions MlpOptionsFor(const DeformationFieldOptions& o, int expression_dims) {
  nn::FrequencyMlpOptions m;
  m.encoding.input_dims = 3;
  m.encoding.num_frequencies = o.num_frequencies;
  m.encoding.include_input = true;
  m.condition_dims = expression_dims;
  m.hidden = o.hidden;
  m.output_dims = 3;
  m.output_activation = nn::Activation::kNone;
  m.output_init_scale = o.output_init_scale;
  m.bf16_inference = o.bf16_inference;
  m.bf16_training = o.bf16_training;
  return m;
}
}  // namespace

Status DeformationFieldOptions::Validate() const {
  if (num_frequencies < 0 || num_frequencies > 16) return Status::Error("num_frequencies must be in [0, 16]");
  if (hidden.empty()) return Status::Error("hidden must have at least one layer");
  for (int w : hidden)
    if (w < 1) return Status::Error("hidden widths must be >= 1");
  if (!(output_init_scale > 0) || !std::isfinite(output_init_scale))
    return Status::Error("output_init_scale must be positive");
  return Status::Ok();
}

std::string DeformationFieldOptions::ToString() const {
  std::ostringstream os;
  os << "DeformationFieldOptions(num_frequencies=" << num_frequencies << ", hidden=" << hidden.size() << "x"
     << (hidden.empty() ? 0 : hidden[0]) << ", output_init_scale=" << output_init_scale << ")";
  return os.str();
}

DeformationField::DeformationField(const DeformationFieldOptions& options, int expression_dims,
                                   const Aabb& aabb, nn::ParameterStore* store, const std::string& name,
                                   int group)
    : options_(options),
      expression_dims_(expression_dims),
      aabb_(aabb),
      half_extent_(0.5f * aabb.Extent()),
      mlp_(MlpOptionsFor(options, expression_dims), store, name, group) {
  ICEF_CHECK(options.Validate().ok(), options.Validate().message());
  ICEF_CHECK(expression_dims >= 1, "expression_dims must be >= 1");
}

void DeformationField::Initialize(uint64_t seed) { mlp_.Initialize(Mix64(seed ^ 17)); }

void DeformationField::SetAnnealing(double alpha) { mlp_.encoding().SetAlpha(alpha); }

void DeformationField::ToUnit(const Executor& executor, int64_t n, const float* positions,
                              DeformationContext* ctx) const {
  ctx->n = n;
  nn::GrowTo(ctx->unit_positions, n * 3);
  nn::GrowTo(ctx->raw, n * 3);
  float* u = ctx->unit_positions.data();
  const Vec3f lo = aabb_.min, inv = half_extent_.cwiseInverse();
  ParallelFor(executor, n, [&](int64_t b, int64_t e, int) {
    for (int64_t i = b; i < e; ++i)
      for (int a = 0; a < 3; ++a) u[3 * i + a] = (positions[3 * i + a] - lo[a]) * inv[a] - 1.f;
  });
}

void DeformationField::Forward(const Executor& executor, int64_t n, const float* positions,
                               const float* betas, float* offsets, DeformationContext* ctx,
                               bool keep_for_backward) const {
  ToUnit(executor, n, positions, ctx);
  mlp_.Forward(executor, n, ctx->unit_positions.data(), betas, ctx->raw.data(), &ctx->mlp, keep_for_backward);
  const float* raw = ctx->raw.data();
  for (int64_t i = 0; i < n; ++i)
    for (int a = 0; a < 3; ++a) offsets[3 * i + a] = raw[3 * i + a] * half_extent_[a];
}

void DeformationField::Backward(const Executor& executor, int64_t n, const float* d_offsets,
                                DeformationContext* ctx) {
  ICEF_CHECK(ctx->n == n, "Backward batch size differs from Forward");
  nn::GrowTo(ctx->d_raw, n * 3);
  float* d_raw = ctx->d_raw.data();
  for (int64_t i = 0; i < n; ++i)
    for (int a = 0; a < 3; ++a) d_raw[3 * i + a] = d_offsets[3 * i + a] * half_extent_[a];
  mlp_.Backward(executor, n, ctx->unit_positions.data(), ctx->raw.data(), d_raw, &ctx->mlp, nullptr, nullptr);
}

void DeformationField::LinearizedForward(const Executor& executor, int64_t n, const float* positions,
                                         const float* anchors, const float* directions, float* offsets,
                                         DeformationContext* ctx) const {
  ToUnit(executor, n, positions, ctx);
  nn::GrowTo(ctx->tangent, n * 3);
  mlp_.Jvp(executor, n, ctx->unit_positions.data(), anchors, nullptr, directions, ctx->raw.data(),
           ctx->tangent.data(), &ctx->mlp);
  const float* raw = ctx->raw.data();
  const float* tan = ctx->tangent.data();
  for (int64_t i = 0; i < n; ++i)
    for (int a = 0; a < 3; ++a) offsets[3 * i + a] = (raw[3 * i + a] + tan[3 * i + a]) * half_extent_[a];
}

std::string DeformationField::ToString() const {
  return "DeformationField(" + options_.ToString() + ", expression_dims=" + std::to_string(expression_dims_) +
         ")";
}

}  // namespace icef
