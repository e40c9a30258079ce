#include "icef/nn/mlp.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "icef/core/rng.h"
#include "icef/nn/scratch_pool.h"

namespace icef::nn {

MlpShape::MlpShape(std::vector<int> widths, Activation output_activation)
    : widths_(std::move(widths)), output_activation_(output_activation) {
  ICEF_CHECK(widths_.size() >= 2, "an MLP needs at least input and output widths");
  weight_offsets_.push_back(0);
  hidden_offsets_.push_back(0);
  for (size_t l = 0; l + 1 < widths_.size(); ++l) {
    ICEF_CHECK(widths_[l] > 0 && widths_[l + 1] > 0, "MLP widths must be positive");
    weight_offsets_.push_back(weight_offsets_.back() + int64_t{widths_[l]} * widths_[l + 1]);
    if (l + 2 < widths_.size()) hidden_offsets_.push_back(hidden_offsets_.back() + widths_[l + 1]);
  }
  max_width_ = *std::max_element(widths_.begin(), widths_.end());
}

std::string MlpShape::ToString() const {
  std::ostringstream s;
  s << "MlpShape(";
  for (size_t i = 0; i < widths_.size(); ++i) s << (i ? " -> " : "") << widths_[i];
  s << ", out=" << ActivationName(output_activation_) << ", params=" << num_params() << ")";
  return s.str();
}

Status MlpOptions::Validate() const {
  if (widths.size() < 2) return Status::Error("mlp.widths: need at least input and output widths");
  for (size_t i = 0; i < widths.size(); ++i) {
    if (widths[i] <= 0) return Status::Error("mlp.widths[" + std::to_string(i) + "]: must be > 0");
  }
  if (!(output_init_scale > 0.0f) || !std::isfinite(output_init_scale)) {
    return Status::Error("mlp.output_init_scale: must be finite and > 0");
  }
  return Status::Ok();
}

std::string MlpOptions::ToString() const {
  return MlpShape(widths, output_activation).ToString() +
         " output_init_scale=" + std::to_string(output_init_scale);
}

Mlp::Mlp(const MlpOptions& options, ParameterStore* store, const std::string& name, int group)
    : options_(options), store_(store) {
  const Status st = options.Validate();
  ICEF_CHECK(st.ok(), st.message());
  shape_ = MlpShape(options.widths, options.output_activation);
  block_ = store_->Register(name, shape_.num_params(), group);
}

void Mlp::Initialize(uint64_t seed) {
  float* w = weights();
  Rng rng(seed, StreamId("mlp_init"), static_cast<uint64_t>(block_));
  for (int l = 0; l < shape_.num_layers(); ++l) {
    const int in = shape_.widths()[l], out = shape_.widths()[l + 1];
    const bool last = l == shape_.num_layers() - 1;
    const double bound =
        last ? std::sqrt(6.0 / (in + out)) * options_.output_init_scale : std::sqrt(6.0 / in);
    float* wl = w + shape_.WeightOffset(l);
    for (int64_t i = 0; i < int64_t{in} * out; ++i) wl[i] = static_cast<float>(rng.Uniform(-bound, bound));
  }
}

namespace {
// Per-thread tile scratch, large enough for backward and JVP.
int64_t ScratchPerThread(const MlpShape& s) {
  return std::max(
      {MlpBackwardScratch(s, kMlpTile), MlpJvpScratch(s, kMlpTile), kMlpTile * s.hidden_per_sample()});
}
template <typename V>
void GrowTo(V* v, size_t n) {
  if (v->size() < n) v->resize(n);
}
}  // namespace

void Mlp::Forward(const Executor& executor, int64_t n, const float* x, float* y, MlpContext* ctx,
                  bool keep_for_backward) const {
  ICEF_CHECK(ctx != nullptr, "Mlp::Forward needs a context");
  const int threads = std::min(executor.num_threads(), 64);
  SlotAllocator slots(threads);
  const int64_t per_thread = ScratchPerThread(shape_);
  GrowTo(&ctx->scratch, static_cast<size_t>(per_thread * threads));
  if (keep_for_backward) {
    GrowTo(&ctx->hidden, static_cast<size_t>(n * shape_.hidden_per_sample()));
    ctx->n = n;
    ctx->num_threads = threads;
  }
  const float* w = weights();
  const MlpBf16Weights* bf = nullptr;
  if ((keep_for_backward ? options_.bf16_training : options_.bf16_inference) && Bf16Supported()) {
    ctx->bf16.Pack(shape_, w);
    bf = &ctx->bf16;
  }
  const int hps = shape_.hidden_per_sample();
  const int in_w = input_dims(), out_w = output_dims();
  ParallelForChunks(executor, n, MlpChunkSize(n), [&](int64_t begin, int64_t end) {
    const SlotAllocator::Slot slot(&slots);
    const int t = slot.index();
    float* scratch = ctx->scratch.data() + per_thread * t;
    for (int64_t s = begin; s < end; s += kMlpTile) {
      const int64_t m = std::min(kMlpTile, end - s);
      float* hidden = keep_for_backward ? ctx->hidden.data() + s * hps : scratch;
      MlpForward<float>(shape_, w, m, x + s * in_w, hidden, y + s * out_w, bf);
    }
  });
}

void Mlp::Backward(const Executor& executor, int64_t n, const float* x, const float* y, const float* dy,
                   MlpContext* ctx, float* dx) {
  ICEF_CHECK(ctx != nullptr && ctx->n == n,
             "Mlp::Backward must follow Forward(keep_for_backward) on the same batch");
  const int threads = std::min(executor.num_threads(), 64);
  SlotAllocator slots(threads);
  const int64_t per_thread = ScratchPerThread(shape_);
  GrowTo(&ctx->scratch, static_cast<size_t>(per_thread * threads));
  const int64_t np = num_params();
  const int64_t chunk = MlpChunkSize(n), chunks = (n + chunk - 1) / chunk;
  GrowTo(&ctx->weight_grads, static_cast<size_t>(np * chunks));
  GrowTo(&ctx->w_transposed, static_cast<size_t>(np));
  MlpTransposeWeights<float>(shape_, weights(), ctx->w_transposed.data());
  const MlpBf16Weights* bf_t = nullptr;
  if (options_.bf16_training && Bf16Supported()) {
    ctx->bf16_transposed.PackTransposed(shape_, ctx->w_transposed.data());
    bf_t = &ctx->bf16_transposed;
  }
  const int hps = shape_.hidden_per_sample();
  const int in_w = input_dims(), out_w = output_dims();
  ParallelForChunks(executor, n, MlpChunkSize(n), [&](int64_t begin, int64_t end) {
    const SlotAllocator::Slot slot(&slots);
    float* scratch = ctx->scratch.data() + per_thread * slot.index();
    // [begin, end) is one chunk, or all of them on a single thread.
    for (int64_t c0 = begin; c0 < end; c0 += chunk) {
      float* dw = ctx->weight_grads.data() + np * (c0 / chunk);
      std::fill(dw, dw + np, 0.0f);
      const int64_t c1 = std::min(end, c0 + chunk);
      for (int64_t s = c0; s < c1; s += kMlpTile) {
        const int64_t m = std::min(kMlpTile, c1 - s);
        MlpBackward<float>(shape_, ctx->w_transposed.data(), m, x + s * in_w, ctx->hidden.data() + s * hps,
                           y + s * out_w, dy + s * out_w, dw, dx ? dx + s * in_w : nullptr, scratch, bf_t);
      }
    }
  });
  float* g = weight_grads();
  for (int64_t c = 0; c < chunks; ++c) {
    const float* dw = ctx->weight_grads.data() + np * c;
    for (int64_t i = 0; i < np; ++i) g[i] += dw[i];
  }
}

void Mlp::Jvp(const Executor& executor, int64_t n, const float* x, int slice_begin, int slice_dims,
              const float* v, float* y, float* jy, MlpContext* ctx) const {
  ICEF_CHECK(slice_begin >= 0 && slice_dims > 0 && slice_begin + slice_dims <= input_dims(),
             "Mlp::Jvp: slice outside the input");
  const int threads = std::min(executor.num_threads(), 64);
  SlotAllocator slots(threads);
  const int64_t per_thread = ScratchPerThread(shape_);
  GrowTo(&ctx->scratch, static_cast<size_t>(per_thread * threads));
  const float* w = weights();
  const int in_w = input_dims(), out_w = output_dims();
  ParallelForChunks(executor, n, MlpChunkSize(n), [&](int64_t begin, int64_t end) {
    const SlotAllocator::Slot slot(&slots);
    const int t = slot.index();
    float* scratch = ctx->scratch.data() + per_thread * t;
    for (int64_t s = begin; s < end; s += kMlpTile) {
      const int64_t m = std::min(kMlpTile, end - s);
      MlpJvp<float>(shape_, w, m, x + s * in_w, slice_begin, slice_dims, v + s * slice_dims, y + s * out_w,
                    jy + s * out_w, scratch);
    }
  });
}

std::string Mlp::ToString() const {
  return "Mlp(" + store_->block(block_).name + ", " + shape_.ToString() + ")";
}

}  // namespace icef::nn
