#include "icef/nn/frequency_mlp.h"

#include "icef/nn/scratch_pool.h"

namespace icef::nn {

Status FrequencyMlpOptions::Validate() const {
  ICEF_RETURN_IF_ERROR(encoding.Validate());
  if (condition_dims < 0) return Status::Error("frequency_mlp.condition_dims: must be >= 0");
  if (output_dims < 1) return Status::Error("frequency_mlp.output_dims: must be >= 1");
  return ToMlpOptions().Validate();
}

MlpOptions FrequencyMlpOptions::ToMlpOptions() const {
  MlpOptions m;
  m.widths.clear();
  m.widths.push_back(encoding.output_dims() + condition_dims);
  for (int h : hidden) m.widths.push_back(h);
  m.widths.push_back(output_dims);
  m.output_activation = output_activation;
  m.output_init_scale = output_init_scale;
  m.bf16_inference = bf16_inference;
  m.bf16_training = bf16_training;
  return m;
}

std::string FrequencyMlpOptions::ToString() const {
  return "FrequencyMlpOptions(" + encoding.ToString() + ", condition_dims=" + std::to_string(condition_dims) +
         ", " + ToMlpOptions().ToString() + ")";
}

FrequencyMlp::FrequencyMlp(const FrequencyMlpOptions& options, ParameterStore* store, const std::string& name,
                           int group)
    : options_(options), encoding_(options.encoding), mlp_(options.ToMlpOptions(), store, name, group) {}

namespace {
int64_t PerThread(const MlpShape& s) {
  return FrequencyMlpScratch(s, kMlpTile) + kMlpTile * (s.input_dims() + s.hidden_per_sample());
}
}  // namespace

void FrequencyMlp::Forward(const Executor& executor, int64_t n, const float* x, const float* c, float* y,
                           FrequencyMlpContext* ctx, bool keep_for_backward) const {
  const MlpShape& s = mlp_.shape();
  const int threads = std::min(executor.num_threads(), 64);
  SlotAllocator slots(threads);
  const int64_t per_thread = PerThread(s);
  if (ctx->scratch.size() < static_cast<size_t>(per_thread * threads))
    ctx->scratch.resize(per_thread * threads);
  const int w0 = s.input_dims(), hps = s.hidden_per_sample(), out = s.output_dims();
  const int d = options_.encoding.input_dims, dc = options_.condition_dims;
  if (keep_for_backward) {
    if (ctx->input.size() < static_cast<size_t>(n * w0)) ctx->input.resize(n * w0);
    if (ctx->mlp.hidden.size() < static_cast<size_t>(n * hps)) ctx->mlp.hidden.resize(n * hps);
    ctx->n = ctx->mlp.n = n;
    ctx->num_threads = ctx->mlp.num_threads = threads;
  }
  const float* w = mlp_.weights();
  const float* fw = encoding_.weights().data();
  const MlpBf16Weights* bf = nullptr;
  if ((keep_for_backward ? options_.bf16_training : options_.bf16_inference) && Bf16Supported()) {
    ctx->mlp.bf16.Pack(s, w);
    bf = &ctx->mlp.bf16;
  }
  ParallelForChunks(executor, n, MlpChunkSize(n), [&](int64_t begin, int64_t end) {
    const SlotAllocator::Slot slot(&slots);
    const int t = slot.index();
    float* scratch = ctx->scratch.data() + per_thread * t;
    float* tile_in = scratch + FrequencyMlpScratch(s, kMlpTile);
    float* tile_hidden = tile_in + kMlpTile * w0;
    for (int64_t r = begin; r < end; r += kMlpTile) {
      const int64_t m = std::min(kMlpTile, end - r);
      float* in = keep_for_backward ? ctx->input.data() + r * w0 : tile_in;
      float* hidden = keep_for_backward ? ctx->mlp.hidden.data() + r * hps : tile_hidden;
      FrequencyMlpForward<float>(options_.encoding, fw, s, w, m, x + r * d, c + r * dc, in, hidden,
                                 y + r * out, scratch, bf);
    }
  });
}

void FrequencyMlp::Backward(const Executor& executor, int64_t n, const float* x, const float* y,
                            const float* dy, FrequencyMlpContext* ctx, float* dx, float* dc_out) {
  ICEF_CHECK(ctx->n == n, "FrequencyMlp::Backward must follow Forward(keep_for_backward) on the same batch");
  const MlpShape& s = mlp_.shape();
  const int threads = std::min(executor.num_threads(), 64);
  SlotAllocator slots(threads);
  const int64_t per_thread = PerThread(s);
  if (ctx->scratch.size() < static_cast<size_t>(per_thread * threads))
    ctx->scratch.resize(per_thread * threads);
  const int64_t np = s.num_params();
  const int64_t chunk = MlpChunkSize(n), chunks = (n + chunk - 1) / chunk;
  MlpContext& mc = ctx->mlp;
  if (mc.weight_grads.size() < static_cast<size_t>(np * chunks)) mc.weight_grads.resize(np * chunks);
  if (mc.w_transposed.size() < static_cast<size_t>(np)) mc.w_transposed.resize(np);
  MlpTransposeWeights<float>(s, mlp_.weights(), mc.w_transposed.data());
  const MlpBf16Weights* bf_t = nullptr;
  if (options_.bf16_training && Bf16Supported()) {
    mc.bf16_transposed.PackTransposed(s, mc.w_transposed.data());
    bf_t = &mc.bf16_transposed;
  }
  const int w0 = s.input_dims(), hps = s.hidden_per_sample(), out = s.output_dims();
  const int d = options_.encoding.input_dims, dc = options_.condition_dims;
  const float* fw = encoding_.weights().data();
  ParallelForChunks(executor, n, MlpChunkSize(n), [&](int64_t begin, int64_t end) {
    const SlotAllocator::Slot slot(&slots);
    float* scratch = ctx->scratch.data() + per_thread * slot.index();
    for (int64_t c0 = begin; c0 < end; c0 += chunk) {
      float* dw = mc.weight_grads.data() + np * (c0 / chunk);
      std::fill(dw, dw + np, 0.0f);
      const int64_t c1 = std::min(end, c0 + chunk);
      for (int64_t r = c0; r < c1; r += kMlpTile) {
        const int64_t m = std::min(kMlpTile, c1 - r);
        FrequencyMlpBackward<float>(options_.encoding, fw, s, mc.w_transposed.data(), m, x + r * d,
                                    ctx->input.data() + r * w0, mc.hidden.data() + r * hps, y + r * out,
                                    dy + r * out, dw, dx ? dx + r * d : nullptr,
                                    dc_out ? dc_out + r * dc : nullptr, scratch, bf_t);
      }
    }
  });
  float* g = mlp_.weight_grads();
  for (int64_t c = 0; c < chunks; ++c) {
    const float* dw = mc.weight_grads.data() + np * c;
    for (int64_t i = 0; i < np; ++i) g[i] += dw[i];
  }
}

void FrequencyMlp::Jvp(const Executor& executor, int64_t n, const float* x, const float* c, const float* vx,
                       const float* vc, float* y, float* jy, FrequencyMlpContext* ctx) const {
  const MlpShape& s = mlp_.shape();
  const int threads = std::min(executor.num_threads(), 64);
  SlotAllocator slots(threads);
  const int64_t per_thread = PerThread(s);
  if (ctx->scratch.size() < static_cast<size_t>(per_thread * threads))
    ctx->scratch.resize(per_thread * threads);
  const int out = s.output_dims();
  const int d = options_.encoding.input_dims, dc = options_.condition_dims;
  const float* w = mlp_.weights();
  const float* fw = encoding_.weights().data();
  const MlpBf16Weights* bf = nullptr;
  if (options_.bf16_inference && Bf16Supported()) {
    ctx->mlp.bf16.Pack(s, w);
    bf = &ctx->mlp.bf16;
  }
  ParallelForChunks(executor, n, MlpChunkSize(n), [&](int64_t begin, int64_t end) {
    const SlotAllocator::Slot slot(&slots);
    const int t = slot.index();
    float* scratch = ctx->scratch.data() + per_thread * t;
    for (int64_t r = begin; r < end; r += kMlpTile) {
      const int64_t m = std::min(kMlpTile, end - r);
      FrequencyMlpJvp<float>(options_.encoding, fw, s, w, m, x + r * d, c + r * dc, vx ? vx + r * d : nullptr,
                             vc ? vc + r * dc : nullptr, y + r * out, jy + r * out, scratch, bf);
    }
  });
}

std::string FrequencyMlp::ToString() const {
  return "FrequencyMlp(" + encoding_.ToString() + ", " + mlp_.ToString() + ")";
}

}  // namespace icef::nn
