#include "icef/nn/reference_model.h"

#include <chrono>
#include <cmath>
#include <sstream>

#include "icef/core/rng.h"
#include "icef/math/ray.h"

namespace icef::nn {

namespace {

using Clock = std::chrono::steady_clock;
double Seconds(Clock::time_point a, Clock::time_point b) {
  return std::chrono::duration<double>(b - a).count();
}

constexpr int kMlpGroup = 0;
constexpr int kGridGroup = 1;
constexpr float kSigmaWeight = 0.01f;

FrequencyMlpOptions DeformOptions() {
  FrequencyMlpOptions o;
  o.encoding.input_dims = 3;
  o.encoding.num_frequencies = 6;
  o.encoding.include_input = true;
  o.condition_dims = kReferenceExpressionDims;
  o.hidden = {64, 64, 64};
  o.output_dims = 3;
  o.output_init_scale = 0.01f;
  return o;
}
MlpOptions DensityOptions() {
  MlpOptions o;
  o.widths = {32, 64, 16};
  return o;
}
MlpOptions ColourOptions() {
  MlpOptions o;
  o.widths = {32, 64, 64, 3};
  o.output_activation = Activation::kSigmoid;
  return o;
}
AdamOptions ReferenceAdam() {
  AdamOptions o;
  o.groups.resize(2);
  o.groups[kMlpGroup].learning_rate = 1e-3;
  o.groups[kGridGroup].learning_rate = 1e-2;
  o.groups[kGridGroup].sparse = true;
  for (AdamGroup& g : o.groups) {
    g.beta1 = 0.9;
    g.beta2 = 0.99;
    g.epsilon = 1e-15;
  }
  return o;
}

}  // namespace

ReferenceBatch MakeReferenceBatch(int64_t num_rays, int samples_per_ray, uint64_t seed) {
  ReferenceBatch b;
  b.num_rays = num_rays;
  b.samples_per_ray = samples_per_ray;
  const int64_t n = b.num_samples();
  b.positions.resize(n * 3);
  b.directions.resize(n * 3);
  b.targets.resize(n * 3);
  b.betas.resize(num_rays * kReferenceExpressionDims);
  const Aabb box;
  for (int64_t r = 0; r < num_rays; ++r) {
    Rng rng(seed, StreamId("reference_batch"), 0, static_cast<uint64_t>(r));
    Vec3f o(static_cast<float>(rng.Normal()), static_cast<float>(rng.Normal()), static_cast<float>(rng.Normal()));
    o = 3.0f * o.normalized();
    const Vec3f target(rng.Uniform(-0.3, 0.3), rng.Uniform(-0.3, 0.3), rng.Uniform(-0.3, 0.3));
    const Ray ray{o, (target - o).normalized()};
    const Interval iv = box.Intersect(ray).value_or(Interval{2.0f, 4.0f});
    for (int k = 0; k < samples_per_ray; ++k) {
      const int64_t s = r * samples_per_ray + k;
      const float t = iv.t_near + (k + 0.5f) / samples_per_ray * (iv.t_far - iv.t_near);
      const Vec3f p = ray.At(t).cwiseMax(-1.0f).cwiseMin(1.0f);
      for (int a = 0; a < 3; ++a) {
        b.positions[3 * s + a] = p[a];
        b.directions[3 * s + a] = ray.direction[a];
        b.targets[3 * s + a] = rng.Uniform();
      }
    }
    for (int j = 0; j < kReferenceExpressionDims; ++j) {
      b.betas[r * kReferenceExpressionDims + j] = static_cast<float>(rng.Uniform(-1.0, 1.0));
    }
  }
  return b;
}

std::string ReferenceTimings::ToString() const {
  std::ostringstream s;
  const double total = fused_tiles + grid_scatter + reduce + adam;
  auto pct = [&](double v) { return total > 0 ? 100.0 * v / total : 0.0; };
  s.precision(3);
  s << "ReferenceTimings(steps=" << steps << ", per step: fused " << 1e3 * fused_tiles / std::max<int64_t>(steps, 1)
    << " ms (" << pct(fused_tiles) << "%), grid scatter " << 1e3 * grid_scatter / std::max<int64_t>(steps, 1)
    << " ms (" << pct(grid_scatter) << "%), reduce " << 1e3 * reduce / std::max<int64_t>(steps, 1) << " ms ("
    << pct(reduce) << "%), adam " << 1e3 * adam / std::max<int64_t>(steps, 1) << " ms (" << pct(adam) << "%))";
  return s.str();
}

struct ReferenceModel::ThreadBuffers {
  explicit ThreadBuffers(const ReferenceModel& m) {
    constexpr int64_t T = kReferenceTile;
    const MlpShape& ds = m.deform_.mlp().shape();
    beta.resize(T * kReferenceExpressionDims);
    def_in.resize(T * ds.input_dims());
    def_hidden.resize(T * ds.hidden_per_sample());
    g.resize(T * 3);
    p.resize(T * 3);
    feat.resize(T * 32);
    dfeat.resize(T * 32);
    jac.resize(T * 32 * 3);
    dens_hidden.resize(T * m.density_.shape().hidden_per_sample());
    dens_out.resize(T * 16);
    col_in.resize(T * 32);
    col_hidden.resize(T * m.colour_.shape().hidden_per_sample());
    rgb.resize(T * 3);
    drgb.resize(T * 3);
    d_col_in.resize(T * 32);
    d_dens_out.resize(T * 16);
    dp.resize(T * 3);
    scratch.resize(std::max({FrequencyMlpScratch(ds, T), MlpBackwardScratch(m.density_.shape(), T),
                             MlpBackwardScratch(m.colour_.shape(), T)}));
  }
  AlignedVector<float> beta, dfeat, def_in, def_hidden, g, p, feat, jac, dens_hidden, dens_out, col_in,
      col_hidden, rgb, drgb, d_col_in, d_dens_out, dp, scratch;
};

ReferenceModel::ReferenceModel(uint64_t seed)
    : grid_(ReferenceHashGridOptions(), &store_, "static/hash_grid", kGridGroup),
      deform_(DeformOptions(), &store_, "deform/mlp", kMlpGroup),
      density_(DensityOptions(), &store_, "static/density_mlp", kMlpGroup),
      colour_(ColourOptions(), &store_, "static/colour_mlp", kMlpGroup),
      sh_(ShEncodingOptions{4}) {
  grid_.Initialize(seed);
  deform_.Initialize(seed);
  density_.Initialize(seed);
  colour_.Initialize(seed);
  adam_ = std::make_unique<Adam>(ReferenceAdam(), &store_);
  wt_deform_.resize(deform_.mlp().num_params());
  wt_density_.resize(density_.num_params());
  wt_colour_.resize(colour_.num_params());
}

ReferenceModel::~ReferenceModel() = default;

int64_t ReferenceModel::MlpMacsPerSample() const {
  return deform_.mlp().num_params() + density_.num_params() + colour_.num_params();
}

void ReferenceModel::EnsureBuffers(int64_t n) {
  if (!pool_) pool_ = std::make_unique<ScratchPool<ThreadBuffers>>();
  if (canonical_.size() < static_cast<size_t>(n * 3)) canonical_.resize(n * 3);
  if (d_features_.size() < static_cast<size_t>(n * 32)) d_features_.resize(n * 32);
}

void ReferenceModel::ForwardTile(ThreadBuffers& b, const ReferenceBatch& batch, int64_t s0, int64_t m,
                                 bool train, float* rgb_sigma) {
  const int spr = batch.samples_per_ray;
  const float* x = batch.positions.data() + 3 * s0;
  for (int64_t i = 0; i < m; ++i) {
    const float* src = batch.betas.data() + ((s0 + i) / spr) * kReferenceExpressionDims;
    std::copy(src, src + kReferenceExpressionDims, b.beta.data() + i * kReferenceExpressionDims);
  }
  // Deformation: g = DeformMlp([freq(x), beta]); canonical p = (x + g + 1) / 2.
  FrequencyMlpForward<float>(deform_.options().encoding, deform_.encoding().weights().data(),
                             deform_.mlp().shape(), deform_.mlp().weights(), m, x, b.beta.data(),
                             b.def_in.data(), b.def_hidden.data(), b.g.data(), b.scratch.data());
  float* p = train ? canonical_.data() + 3 * s0 : b.p.data();
  for (int64_t i = 0; i < 3 * m; ++i) p[i] = 0.5f * (x[i] + b.g[i] + 1.0f);
  // Static field.
  grid_.ForwardTile(m, p, b.feat.data(), train ? b.jac.data() : nullptr);
  MlpForward<float>(density_.shape(), density_.weights(), m, b.feat.data(), b.dens_hidden.data(),
                    b.dens_out.data());
  const float* dir = batch.directions.data() + 3 * s0;
  for (int64_t i = 0; i < m; ++i) {
    float* row = b.col_in.data() + i * 32;
    std::copy(b.dens_out.data() + i * 16, b.dens_out.data() + (i + 1) * 16, row);
    ShBasis<float>(4, dir[3 * i], dir[3 * i + 1], dir[3 * i + 2], row + 16);
  }
  MlpForward<float>(colour_.shape(), colour_.weights(), m, b.col_in.data(), b.col_hidden.data(), b.rgb.data());
  if (rgb_sigma) {
    for (int64_t i = 0; i < m; ++i) {
      float* o = rgb_sigma + (s0 + i) * 4;
      o[0] = b.rgb[3 * i];
      o[1] = b.rgb[3 * i + 1];
      o[2] = b.rgb[3 * i + 2];
      o[3] = std::exp(b.dens_out[16 * i]);
    }
  }
}

double ReferenceModel::BackwardTile(ThreadBuffers& b, const ReferenceBatch& batch, int64_t s0, int64_t m,
                                    float* dw) {
  float* dw_deform = dw;
  float* dw_density = dw_deform + deform_.mlp().num_params();
  float* dw_colour = dw_density + density_.num_params();
  const float inv_n = 1.0f / static_cast<float>(batch.num_samples());
  const float* target = batch.targets.data() + 3 * s0;
  double loss = 0.0;
  for (int64_t i = 0; i < m; ++i) {
    const float sigma = std::exp(b.dens_out[16 * i]);
    double l = kSigmaWeight * sigma;
    for (int a = 0; a < 3; ++a) {
      const float r = b.rgb[3 * i + a] - target[3 * i + a];
      l += r * r;
      b.drgb[3 * i + a] = 2.0f * r * inv_n;
    }
    loss += l;
  }
  // Colour MLP -> d [dens_out, sh]; density MLP -> d features (kept for pass 2).
  MlpBackward<float>(colour_.shape(), wt_colour_.data(), m, b.col_in.data(), b.col_hidden.data(),
                     b.rgb.data(), b.drgb.data(), dw_colour, b.d_col_in.data(), b.scratch.data());
  for (int64_t i = 0; i < m; ++i) {
    std::copy(b.d_col_in.data() + i * 32, b.d_col_in.data() + i * 32 + 16, b.d_dens_out.data() + i * 16);
    b.d_dens_out[16 * i] += kSigmaWeight * inv_n * std::exp(b.dens_out[16 * i]);
  }
  float* d_feat = b.dfeat.data();
  MlpBackward<float>(density_.shape(), wt_density_.data(), m, b.feat.data(), b.dens_hidden.data(),
                     b.dens_out.data(), b.d_dens_out.data(), dw_density, d_feat, b.scratch.data());
  // Through the grid to the canonical position, then into the deformation net (dp/dg = 1/2).
  HashGridBackwardInput<float>(grid_.layout(), m, b.jac.data(), d_feat, b.dp.data());
  // Level-major copy for the scatter pass: d_features_[l][s][2].
  const int64_t n = batch.num_samples();
  for (int l = 0; l < grid_.layout().num_levels; ++l) {
    float* dst = d_features_.data() + (l * n + s0) * 2;
    for (int64_t i = 0; i < m; ++i) {
      dst[2 * i] = d_feat[32 * i + 2 * l];
      dst[2 * i + 1] = d_feat[32 * i + 2 * l + 1];
    }
  }
  for (int64_t i = 0; i < 3 * m; ++i) b.dp[i] *= 0.5f;
  FrequencyMlpBackward<float>(deform_.options().encoding, deform_.encoding().weights().data(),
                              deform_.mlp().shape(), wt_deform_.data(), m, batch.positions.data() + 3 * s0,
                              b.def_in.data(), b.def_hidden.data(), b.g.data(), b.dp.data(),
                              dw_deform, nullptr, nullptr, b.scratch.data());
  return loss;
}

double ReferenceModel::ForwardBackward(const Executor& executor, const ReferenceBatch& batch) {
  const int64_t n = batch.num_samples();
  EnsureBuffers(n);
  MlpTransposeWeights<float>(deform_.mlp().shape(), deform_.mlp().weights(), wt_deform_.data());
  MlpTransposeWeights<float>(density_.shape(), density_.weights(), wt_density_.data());
  MlpTransposeWeights<float>(colour_.shape(), colour_.weights(), wt_colour_.data());
  const int64_t params = MlpMacsPerSample();  // = MLP parameter count (no biases)
  const int64_t chunks = (n + kReferenceChunk - 1) / kReferenceChunk;
  if (chunk_grads_.size() < static_cast<size_t>(chunks * params)) chunk_grads_.resize(chunks * params);
  chunk_loss_.assign(chunks, 0.0);
  const auto t0 = Clock::now();
  ParallelForChunks(executor, n, kReferenceChunk, [&](int64_t begin, int64_t end) {
    auto b = pool_->Borrow([this] { return std::make_unique<ThreadBuffers>(*this); });
    // begin/end cover whole chunks (one, or all of them when running on one thread).
    for (int64_t c0 = begin; c0 < end; c0 += kReferenceChunk) {
      const int64_t c = c0 / kReferenceChunk;
      const int64_t c1 = std::min(end, c0 + kReferenceChunk);
      float* dw = chunk_grads_.data() + c * params;
      std::fill(dw, dw + params, 0.0f);
      double loss = 0.0;
      for (int64_t s = c0; s < c1; s += kReferenceTile) {
        const int64_t m = std::min(kReferenceTile, c1 - s);
        ForwardTile(*b, batch, s, m, /*train=*/true, nullptr);
        loss += BackwardTile(*b, batch, s, m, dw);
      }
      chunk_loss_[c] = loss;
    }
  });
  const auto t1 = Clock::now();
  {
    // One level per work item, most expensive (hashed, finest) first.
    const int levels = grid_.layout().num_levels;
    ParallelForChunks(executor, levels, 1, [&](int64_t begin, int64_t end) {
      for (int64_t i = begin; i < end; ++i) {
        const int l = levels - 1 - static_cast<int>(i);
        grid_.BackwardParamsLevel(l, n, canonical_.data(), d_features_.data() + int64_t{l} * n * 2, 2);
      }
    });
  }
  const auto t2 = Clock::now();
  double loss = 0.0;
  float* g_deform = deform_.mlp().weight_grads();
  float* g_density = density_.weight_grads();
  float* g_colour = colour_.weight_grads();
  const int64_t p0 = deform_.mlp().num_params(), p1 = density_.num_params();
  for (int64_t c = 0; c < chunks; ++c) {
    loss += chunk_loss_[c];
    const float* dw = chunk_grads_.data() + c * params;
    for (int64_t i = 0; i < p0; ++i) g_deform[i] += dw[i];
    for (int64_t i = 0; i < p1; ++i) g_density[i] += dw[p0 + i];
    for (int64_t i = 0; i < params - p0 - p1; ++i) g_colour[i] += dw[p0 + p1 + i];
  }
  const auto t3 = Clock::now();
  timings_.fused_tiles += Seconds(t0, t1);
  timings_.grid_scatter += Seconds(t1, t2);
  timings_.reduce += Seconds(t2, t3);
  ++timings_.steps;
  return loss / static_cast<double>(n);
}

void ReferenceModel::OptimizerStep(const Executor& executor) {
  const auto t0 = Clock::now();
  adam_->Step(executor);
  timings_.adam += Seconds(t0, Clock::now());
}

void ReferenceModel::Infer(const Executor& executor, const ReferenceBatch& batch, float* rgb_sigma) {
  const int64_t n = batch.num_samples();
  EnsureBuffers(0);
  ParallelForChunks(executor, n, kReferenceChunk, [&](int64_t begin, int64_t end) {
    auto b = pool_->Borrow([this] { return std::make_unique<ThreadBuffers>(*this); });
    for (int64_t s = begin; s < end; s += kReferenceTile) {
      ForwardTile(*b, batch, s, std::min(kReferenceTile, end - s), /*train=*/false, rgb_sigma);
    }
  });
}

}  // namespace icef::nn
