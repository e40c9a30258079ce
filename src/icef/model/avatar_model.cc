#include "icef/model/avatar_model.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "icef/core/rng.h"
#include "icef/model/face_prior.h"
#include "icef/model/model_workspace.h"
#include "icef/render/ray_march.h"

namespace icef {

namespace {
// The face model's open-mouth interior (docs/design.md §2.1): an absorbing volume. Its density makes a
// cavity sample opaque within about a hundredth of the aabb. Its colour is learned, three values
// through a sigmoid, from the open mouths the training frames show (a frame that shows none passes
// it no gradient, and the colour keeps its start, a dark red-brown mouth interior).
constexpr float kCavityDensity = 400.f;
constexpr float kCavityColorStart[3] = {0.12f, 0.04f, 0.04f};
// The teeth of an open mouth (priors with teeth) are as opaque, and their colour is learned the same
// way from the training frames that show them; it starts as the off-white of teeth.
constexpr float kTeethColorStart[3] = {0.86f, 0.82f, 0.74f};
// Density (1/world units) below which a sample is left unshaded by the prior shading.
constexpr float kShadeMinDensity = 0.05f;

float Sigmoid(float v) { return 1.f / (1.f + std::exp(-v)); }

// The density compositing sees at a sample of the prior's material (DeformationPrior::Cavity's
// labels) whose static field density is sigma.
float MaterialDensity(uint8_t material, float sigma) {
  switch (material) {
    case DeformationPrior::kField:
      return sigma;
    case DeformationPrior::kAir:
      return 0.f;
    default:
      return kCavityDensity;
  }
}
// Samples in the cavity or the teeth take their density and colour (colours[3 * (label - 1) +
// channel]); samples in the air between parted lips are empty.
void ApplyCavity(int64_t n, const uint8_t* inside, const float colours[6], float* sigma, float* rgb) {
  for (int64_t i = 0; i < n; ++i) {
    if (!inside[i]) continue;
    sigma[i] = MaterialDensity(inside[i], sigma[i]);
    if (inside[i] == DeformationPrior::kAir) continue;
    for (int a = 0; a < 3; ++a) rgb[3 * i + a] = colours[3 * (inside[i] - 1) + a];
  }
}
// The cavity's (and the teeth's) samples' colour gradients, summed (in sample order, in double) onto
// their colour's logits (d rgb / d logit = rgb (1 - rgb)); then both their gradients are dropped (the
// static field did not produce them). teeth_logits is empty for a prior without teeth.
void CavityBackward(int64_t n, const uint8_t* inside, std::span<const float> cavity_logits,
                    std::span<const float> teeth_logits, float* d_sigma, float* d_rgb,
                    std::span<float> d_cavity_logits, std::span<float> d_teeth_logits) {
  double sum[2][3] = {{0, 0, 0}, {0, 0, 0}};
  for (int64_t i = 0; i < n; ++i) {
    if (!inside[i]) continue;
    ICEF_CHECK(inside[i] != DeformationPrior::kTeeth || !teeth_logits.empty(),
               "teeth samples from a prior without teeth");
    d_sigma[i] = 0.f;
    for (int a = 0; a < 3; ++a) {
      if (inside[i] != DeformationPrior::kAir) sum[inside[i] - 1][a] += d_rgb[3 * i + a];
      d_rgb[3 * i + a] = 0.f;
    }
  }
  const auto add = [](const double* s, std::span<const float> logits, std::span<float> d_logits) {
    for (int a = 0; a < 3; ++a) {
      const double c = Sigmoid(logits[a]);
      d_logits[a] += static_cast<float>(s[a] * c * (1.0 - c));
    }
  };
  add(sum[0], cavity_logits, d_cavity_logits);
  if (!teeth_logits.empty()) add(sum[1], teeth_logits, d_teeth_logits);
}
}  // namespace

AvatarModel::AvatarModel(const ModelConfig& config, const ModelSetup& setup, RegionMask mask,
                         ExpressionConfidence confidence)
    : config_(config),
      setup_(setup),
      method_(config.ParsedMethod()),
      traits_(TraitsOf(method_)),
      mask_(std::move(mask)),
      confidence_(std::move(confidence)),
      occupancy_(setup.aabb, config.occupancy),
      train_ws_(std::make_unique<ModelWorkspace>()),
      render_ws_(std::make_unique<ModelWorkspace>()),
      losses_(MakeLosses()) {}

AvatarModel::~AvatarModel() = default;

Result<std::unique_ptr<AvatarModel>> AvatarModel::Create(const ModelConfig& config, const ModelSetup& setup,
                                                         const Executor& executor,
                                                         std::unique_ptr<DeformationPrior> prior) {
  ICEF_RETURN_IF_ERROR(config.Validate().WithContext("model config"));
  if (!setup.aabb.IsValid()) return Status::Error("model setup: invalid aabb " + setup.aabb.ToString());
  if (setup.expression_dim < 1) return Status::Error("model setup: expression_dim must be >= 1");
  ICEF_ASSIGN_OR_RETURN(RegionMask mask,
                        RegionMask::FromLandmarks(setup.mask_landmarks, config.region_mask, executor));
  ICEF_ASSIGN_OR_RETURN(ExpressionConfidence confidence,
                        ExpressionConfidence::Create(setup.training_expressions, config.confidence));
  if (confidence.expression_dim() != setup.expression_dim)
    return Status::Error("model setup: training expressions do not have expression_dim values");
  std::unique_ptr<AvatarModel> model(new AvatarModel(config, setup, std::move(mask), std::move(confidence)));
  if (Result<SymmetryPlane> plane = SymmetryPlane::FromLandmarks(setup.mask_landmarks); plane.ok())
    model->symmetry_ = *plane;
  model->static_field_ = std::make_unique<StaticField>(config.StaticOptions(setup.expression_dim), setup.aabb,
                                                       &model->store_, "static", kGridGroup, kMlpGroup);
  if (model->traits_.deformation) {
    model->residual_field_ =
        std::make_unique<DeformationField>(config.DeformationOptions(), setup.expression_dim, setup.aabb,
                                           &model->store_, "deformation", kDeformGroup);
  }
  if (model->traits_.prior) {
    if (prior) {
      if (prior->expression_dims() != setup.expression_dim)
        return Status::Error("model setup: the prior's expression_dim differs from the setup's");
      model->prior_ = std::move(prior);
    } else {
      ICEF_ASSIGN_OR_RETURN(model->prior_, MakeFacePrior(setup));
    }
  }
  if (model->residual_field_ || model->prior_) {
    model->warp_ = std::make_unique<Deformation>(model->residual_field_.get(), model->prior_.get(),
                                                 &model->confidence_, model->traits_.confidence);
  }
  if (model->prior_ && config.prior_shading) model->light_ = setup.prior_light;
  if (model->prior_) model->cavity_block_ = model->store_.Register("cavity/colour", 3, kGridGroup);
  if (model->prior_ && model->prior_->has_teeth())
    model->teeth_block_ = model->store_.Register("teeth/colour", 3, kGridGroup);
  return model;
}

void AvatarModel::Initialize(uint64_t seed) {
  static_field_->Initialize(Mix64(seed ^ StreamId("static_field")));
  if (residual_field_) residual_field_->Initialize(Mix64(seed ^ StreamId("deformation_field")));
  if (cavity_block_ >= 0) {
    const std::span<float> logits = store_.params(cavity_block_);
    for (int a = 0; a < 3; ++a) logits[a] = std::log(kCavityColorStart[a] / (1.f - kCavityColorStart[a]));
  }
  if (teeth_block_ >= 0) {
    const std::span<float> logits = store_.params(teeth_block_);
    for (int a = 0; a < 3; ++a) logits[a] = std::log(kTeethColorStart[a] / (1.f - kTeethColorStart[a]));
  }
  occupancy_.Fill(true);
}

NearestExpression AvatarModel::Nearest(std::span<const float> beta) const {
  return confidence_.Nearest(beta);
}

float AvatarModel::CavityColour(int channel) const {
  ICEF_CHECK(cavity_block_ >= 0, "no mouth cavity without a prior");
  return Sigmoid(store_.params(cavity_block_)[channel]);
}

float AvatarModel::TeethColour(int channel) const {
  ICEF_CHECK(teeth_block_ >= 0, "no teeth: the prior has none");
  return Sigmoid(store_.params(teeth_block_)[channel]);
}

void AvatarModel::QueryStatic(const Executor& executor, int64_t n, const float* canonical,
                              const float* directions, const float* condition, float* sigma,
                              float* rgb) const {
  StaticFieldContext ctx;
  static_field_->Forward(executor, n, canonical, directions, condition, sigma, rgb, &ctx, false, false);
}

void AvatarModel::WarpOffsets(const Executor& executor, int64_t n, const float* positions,
                              std::span<const float> beta, float* offsets, WarpPart part) const {
  ICEF_CHECK(static_cast<int>(beta.size()) == setup_.expression_dim, "beta has the wrong length");
  if (!warp_) {
    std::fill(offsets, offsets + 3 * n, 0.f);
    return;
  }
  DeformationWorkspace ws;
  warp_->Offsets(executor, n, positions, beta, offsets, &ws, part);
}

void AvatarModel::Offsets(const Executor& executor, int64_t n, const float* positions,
                          std::span<const float> beta, float* offsets) const {
  WarpOffsets(executor, n, positions, beta, offsets, WarpPart::kFinal);
}

void AvatarModel::OffsetsPhi(const Executor& executor, int64_t n, const float* positions,
                             std::span<const float> beta, float* offsets) const {
  WarpOffsets(executor, n, positions, beta, offsets, WarpPart::kPhi);
}

void AvatarModel::OffsetsLinearized(const Executor& executor, int64_t n, const float* positions,
                                    std::span<const float> beta, float* offsets) const {
  WarpOffsets(executor, n, positions, beta, offsets, WarpPart::kLinearized);
}

void AvatarModel::ExpandRays(const TrainRays& batch, ModelWorkspace& ws, const Executor& executor) const {
  const int64_t n = ws.samples.size();
  const int b = setup_.expression_dim;
  Fit(ws.dirs, 3 * n);
  const bool need_betas = warp_ || traits_.entangled_beta;
  if (need_betas) Fit(ws.betas, n * b);
  ParallelFor(executor, static_cast<int64_t>(batch.rays.size()), [&](int64_t r0, int64_t r1, int) {
    for (int64_t r = r0; r < r1; ++r) {
      const int64_t off = ws.samples.ray_offset[r], cnt = ws.samples.ray_count[r];
      const Vec3f& d = batch.rays[r].direction;
      const std::vector<float>& beta = setup_.training_expressions[batch.frame[r]];
      for (int64_t i = off; i < off + cnt; ++i) {
        for (int a = 0; a < 3; ++a) ws.dirs[3 * i + a] = d[a];
        if (need_betas) std::copy(beta.begin(), beta.end(), ws.betas.begin() + i * b);
      }
    }
  });
}

void AvatarModel::FieldForward(ModelWorkspace& ws, int64_t n, const float* positions, bool train,
                               const Executor& executor, int64_t color_rays) const {
  const float* canonical = positions;
  if (warp_) {
    Fit(ws.canonical, 3 * n);
    ParallelFor(executor, 3 * n, [&](int64_t i0, int64_t i1, int) {
      for (int64_t i = i0; i < i1; ++i) ws.canonical[i] = positions[i] + ws.offsets[i];
    });
    canonical = ws.canonical.data();
  }
  Fit(ws.sigma, n);
  Fit(ws.rgb, 3 * n);
  static_field_->ForwardDensity(executor, n, canonical, traits_.entangled_beta ? ws.betas.data() : nullptr,
                                ws.sigma.data(), &ws.static_ctx, train, train && warp_ != nullptr);
  const bool cavity = warp_ && warp_->has_prior();
  if (cavity) {
    Fit(ws.cavity, n);
    warp_->Cavity(executor, n, positions, ws.betas.data(), ws.cavity.data());
  }
  std::optional<std::span<const int32_t>> rows;
  if (color_rays >= 0) {
    CompositedRows(ws, color_rays, cavity);
    rows = std::span<const int32_t>(ws.color_rows);
  }
  static_field_->ForwardColor(executor, n, ws.dirs.data(), rows, ws.rgb.data(), &ws.static_ctx, train);
  ws.shade.clear();
  if (light_ && ShadingNormals(ws, n, rows, positions, executor)) {
    Fit(ws.shade, n);
    if (train) ws.rgb_unshaded.assign(ws.rgb.begin(), ws.rgb.begin() + 3 * n);
    ApplyPriorShading(executor, n, ws.normals_obs.data(), ws.normals_can.data(), *light_, ws.rgb.data(),
                      ws.shade.data());
  }
  if (cavity) {
    float colours[6] = {CavityColour(0), CavityColour(1), CavityColour(2), 0.f, 0.f, 0.f};
    if (has_teeth())
      for (int a = 0; a < 3; ++a) colours[3 + a] = TeethColour(a);
    ApplyCavity(n, ws.cavity.data(), colours, ws.sigma.data(), ws.rgb.data());
  }
}

void AvatarModel::CompositedRows(ModelWorkspace& ws, int64_t rays, bool cavity) const {
  const float eps = static_cast<float>(config_.compositing.transmittance_eps);  // as CompositeForward's
  ws.color_rows.clear();
  for (int64_t r = 0; r < rays; ++r) {
    const int32_t off = ws.samples.ray_offset[r], cnt = ws.samples.ray_count[r];
    const float* sigma = ws.sigma.data() + off;
    if (cavity) {  // the densities compositing will see, after ApplyCavity
      Fit(ws.ray_sigma, cnt);
      for (int32_t k = 0; k < cnt; ++k) ws.ray_sigma[k] = MaterialDensity(ws.cavity[off + k], sigma[k]);
      sigma = ws.ray_sigma.data();
    }
    const int used = CompositeRayUsed<float>(cnt, sigma, ws.samples.dt.data() + off, eps);
    for (int32_t k = 0; k < used; ++k) ws.color_rows.push_back(off + k);
  }
}

bool AvatarModel::ShadingNormals(ModelWorkspace& ws, int64_t n, std::optional<std::span<const int32_t>> rows,
                                 const float* positions, const Executor& executor) const {
  // The face model's normals cost eight signed-distance evaluations: only at samples dense enough to
  // show (each weighs at most 1 - exp(-kShadeMinDensity dt) in its ray, about 2e-3 at 96 samples
  // across a [-1, 1]^3 aabb); elsewhere both normals are zero, which makes s = 1.
  const int b = setup_.expression_dim;
  ws.shade_index.clear();
  const int64_t candidates = rows ? static_cast<int64_t>(rows->size()) : n;
  for (int64_t j = 0; j < candidates; ++j) {
    const int64_t i = rows ? (*rows)[j] : j;
    if (ws.sigma[i] > kShadeMinDensity) ws.shade_index.push_back(i);
  }
  const int64_t m = static_cast<int64_t>(ws.shade_index.size());
  Fit(ws.shade_positions, 3 * m);
  Fit(ws.shade_betas, m * b);
  ParallelFor(executor, m, [&](int64_t j0, int64_t j1, int) {
    for (int64_t j = j0; j < j1; ++j) {
      const int64_t i = ws.shade_index[j];
      std::copy(positions + 3 * i, positions + 3 * i + 3, ws.shade_positions.begin() + 3 * j);
      std::copy(ws.betas.begin() + i * b, ws.betas.begin() + (i + 1) * b, ws.shade_betas.begin() + j * b);
    }
  });
  Fit(ws.shade_obs, 3 * m);
  Fit(ws.shade_can, 3 * m);
  if (!warp_->Normals(executor, m, ws.shade_positions.data(), ws.shade_betas.data(), ws.shade_obs.data(),
                      ws.shade_can.data()))
    return false;
  ws.normals_obs.assign(3 * n, 0.f);
  ws.normals_can.assign(3 * n, 0.f);
  for (int64_t j = 0; j < m; ++j) {
    const int64_t i = ws.shade_index[j];
    for (int a = 0; a < 3; ++a) {
      ws.normals_obs[3 * i + a] = ws.shade_obs[3 * j + a];
      ws.normals_can[3 * i + a] = ws.shade_can[3 * j + a];
    }
  }
  return true;
}

void AvatarModel::PlaceTrainingSamples(const TrainRays& batch, ModelWorkspace& ws, uint64_t seed,
                                       int64_t step, const Executor& executor) const {
  if (!config_.importance.enabled()) {
    SampleRays(batch.rays, setup_.aabb, config_.SamplerOptions(true), &occupancy_, seed, step, executor,
               &ws.samples);
    return;
  }
  // Coarse pass: the density at the stratified samples, through the warp at each ray's expression.
  SampleRays(batch.rays, setup_.aabb, config_.SamplerOptions(true), &occupancy_, seed, step, executor,
             &ws.coarse);
  const int64_t m = ws.coarse.size();
  const int b = setup_.expression_dim;
  const bool need_betas = warp_ || traits_.entangled_beta;
  if (need_betas) {
    Fit(ws.coarse_betas, m * b);
    ParallelFor(executor, static_cast<int64_t>(batch.rays.size()), [&](int64_t r0, int64_t r1, int) {
      for (int64_t r = r0; r < r1; ++r) {
        const std::vector<float>& beta = setup_.training_expressions[batch.frame[r]];
        for (int64_t i = ws.coarse.ray_offset[r]; i < ws.coarse.ray_offset[r] + ws.coarse.ray_count[r]; ++i)
          std::copy(beta.begin(), beta.end(), ws.coarse_betas.begin() + i * b);
      }
    });
  }
  const float* positions = ws.coarse.positions.data();
  const float* canonical = positions;
  if (warp_) {
    Fit(ws.coarse_offsets, 3 * m);
    Fit(ws.coarse_canonical, 3 * m);
    warp_->ForwardTrain(executor, m, positions, ws.coarse_betas.data(), ws.coarse_offsets.data(), nullptr,
                        &ws.coarse_deform_ctx, false);
    ParallelFor(executor, 3 * m, [&](int64_t i0, int64_t i1, int) {
      for (int64_t i = i0; i < i1; ++i) ws.coarse_canonical[i] = positions[i] + ws.coarse_offsets[i];
    });
    canonical = ws.coarse_canonical.data();
  }
  Fit(ws.coarse_sigma, m);
  static_field_->Density(executor, m, canonical, traits_.entangled_beta ? ws.coarse_betas.data() : nullptr,
                         ws.coarse_sigma.data(), &ws.coarse_static_ctx);
  if (warp_ && warp_->has_prior()) {
    Fit(ws.coarse_cavity, m);
    warp_->Cavity(executor, m, positions, ws.coarse_betas.data(), ws.coarse_cavity.data());
    for (int64_t i = 0; i < m; ++i)
      ws.coarse_sigma[i] = MaterialDensity(ws.coarse_cavity[i], ws.coarse_sigma[i]);
  }
  ResampleRays(batch.rays, ws.coarse, ws.coarse_sigma, config_.importance, seed, step, executor, &ws.samples);
}

LossTerms AvatarModel::TrainForwardBackward(const TrainRays& batch, const LossWeights& weights, uint64_t seed,
                                            int64_t step, const Executor& executor) {
  ModelWorkspace& ws = *train_ws_;
  const int64_t num_rays = static_cast<int64_t>(batch.rays.size());
  PlaceTrainingSamples(batch, ws, seed, step, executor);
  const int64_t n = ws.samples.size();
  ExpandRays(batch, ws, executor);
  if (warp_) {  // observation -> canonical
    Fit(ws.offsets, 3 * n);
    Fit(ws.residual, 3 * n);
    warp_->ForwardTrain(executor, n, ws.samples.positions.data(), ws.betas.data(), ws.offsets.data(),
                        ws.residual.data(), &ws.deform_ctx, true);
  }
  // Colour only what the pixel rays composite (see the header); the unseen views' rays come after
  // them (batch.photo_rays).
  const bool symmetry_colour = weights.lambda_symmetry != 0 && weights.symmetry_colour != 0;
  const int64_t color_rays = color_composited_only_ && !symmetry_colour ? batch.NumPhotoRays() : -1;
  FieldForward(ws, n, ws.samples.positions.data(), true, executor, color_rays);

  // Compositing over the known background.
  const float bg[3] = {setup_.background.x(), setup_.background.y(), setup_.background.z()};
  ICEF_CHECK(batch.background.empty() || int64_t(batch.background.size()) == 3 * num_rays, "background size");
  CompositeInputs<float> in{
      ws.sigma,
      ws.rgb,
      ws.samples.t,
      ws.samples.dt,
      ws.samples.ray_offset,
      ws.samples.ray_count,
      batch.background.empty() ? std::span<const float>(bg, 3) : std::span<const float>(batch.background)};
  CompositeForward(in, config_.compositing, executor, &ws.composite);

  // The loss terms stage by stage along the backward pass: rays, back through compositing to the
  // samples, through the static field to the canonical positions, through the warp.
  LossTerms terms;
  terms.samples = n;
  LossContext ctx{batch,       ws,    weights,   setup_, traits_, *static_field_, residual_field_.get(),
                  warp_.get(), mask_, symmetry_, seed,   step,    executor};
  ws.d_color.assign(3 * num_rays, 0.f);
  ws.d_opacity.assign(num_rays, 0.f);
  ws.d_weights.clear();
  evaluated_losses_.clear();
  RunLosses(LossStage::kRays, ctx, &terms);
  CompositeOutputGradients<float> grads{ws.d_color, ws.d_opacity, {}, ws.d_weights};
  CompositeBackward(in, ws.composite, grads, executor, &ws.d_sigma, &ws.d_rgb);
  RunLosses(LossStage::kSamples, ctx, &terms);
  if (warp_ && warp_->has_prior())
    CavityBackward(n, ws.cavity.data(), store_.params(cavity_block_),
                   has_teeth() ? store_.params(teeth_block_) : std::span<const float>(), ws.d_sigma.data(),
                   ws.d_rgb.data(), store_.grads(cavity_block_),
                   has_teeth() ? store_.grads(teeth_block_) : std::span<float>());
  if (warp_) Fit(ws.d_canonical, 3 * n);
  const bool shaded = !ws.shade.empty();
  if (shaded)  // d rgb_unshaded = s d rgb
    ParallelFor(executor, n, [&](int64_t i0, int64_t i1, int) {
      for (int64_t i = i0; i < i1; ++i)
        for (int a = 0; a < 3; ++a) ws.d_rgb[3 * i + a] *= ws.shade[i];
    });
  static_field_->Backward(executor, n, ws.sigma.data(), shaded ? ws.rgb_unshaded.data() : ws.rgb.data(),
                          ws.d_sigma.data(), ws.d_rgb.data(), &ws.static_ctx,
                          warp_ ? ws.d_canonical.data() : nullptr);
  for (Loss* loss : evaluated_losses_) loss->AfterStaticBackward(ctx);
  RunLosses(LossStage::kCanonical, ctx, &terms);  // the terms on the warp have weight 0 without one
  if (warp_) warp_->Backward(executor, n, ws.d_canonical.data(), &ws.deform_ctx);
  RunLosses(LossStage::kResidual, ctx, &terms);
  return terms;
}

void AvatarModel::RunLosses(LossStage stage, LossContext& ctx, LossTerms* terms) {
  for (const std::unique_ptr<Loss>& loss : losses_) {
    if (loss->stage() != stage) continue;
    LossValue v{std::string(loss->name()), loss->Weight(ctx), 0.0};
    if (v.weight != 0) {
      v.value = loss->Evaluate(ctx, v.weight);
      evaluated_losses_.push_back(loss.get());
    }
    terms->total += v.weight * v.value;
    terms->terms.push_back(std::move(v));
  }
}

OccupancyGrid AvatarModel::RenderOccupancy(std::span<const float> beta, const Executor& executor) const {
  ICEF_CHECK(static_cast<int>(beta.size()) == setup_.expression_dim, "beta has the wrong length");
  if (!warp_ && !traits_.entangled_beta) return occupancy_;  // the density does not depend on beta
  const std::vector<uint8_t>& hull = occupancy_.allowed();
  StaticFieldContext sctx;
  DeformationWorkspace dws;
  std::vector<float> betas, offsets, canonical;
  std::vector<uint8_t> cavity;
  auto query = [&](const float* positions, int64_t n, float* sigma) {
    const float* c = positions;
    if (warp_) {
      offsets.resize(3 * n);
      canonical.resize(3 * n);
      warp_->Offsets(executor, n, positions, beta, offsets.data(), &dws);
      for (int64_t i = 0; i < 3 * n; ++i) canonical[i] = positions[i] + offsets[i];
      c = canonical.data();
    } else {
      BroadcastExpression(beta, n, &betas);
    }
    static_field_->Density(executor, n, c, warp_ ? nullptr : betas.data(), sigma, &sctx);
    for (int64_t i = 0; i < n; ++i) {
      const int64_t cell = occupancy_.CellOf(Vec3f(c[3 * i], c[3 * i + 1], c[3 * i + 2]));
      if (cell < 0 || (!hull.empty() && !hull[cell])) sigma[i] = -1.f;  // not allowed
    }
    if (warp_ && warp_->has_prior()) {  // the open mouth's interior is geometry too
      cavity.resize(n);
      warp_->Cavity(executor, n, positions, dws.betas.data(), cavity.data());
      for (int64_t i = 0; i < n; ++i)
        if (cavity[i]) sigma[i] = MaterialDensity(cavity[i], sigma[i]);
    }
  };
  // One query per 2 x 2 x 2 cells: the training grid already holds the observed geometry, what is
  // added here is bulky (a jaw, lips), and a quarter of a second per image at full resolution
  // (64^3 warps) is not worth it.
  return occupancy_.WithQueriedCells(query, 2);
}

void AvatarModel::Render(std::span<const Ray> rays, std::span<const float> beta, const Vec3f& background,
                         const Executor& executor, RenderOutput* out, const OccupancyGrid* occupancy) const {
  ICEF_CHECK(static_cast<int>(beta.size()) == setup_.expression_dim, "beta has the wrong length");
  ModelWorkspace& ws = *render_ws_;
  const int64_t total_rays = static_cast<int64_t>(rays.size());
  out->color.assign(3 * total_rays, 0.f);
  out->depth.assign(total_rays, 0.f);
  out->opacity.assign(total_rays, 0.f);
  out->mask.assign(total_rays, 0.f);
  out->deformation.assign(total_rays, 0.f);
  out->samples_evaluated = 0;
  const float bg[3] = {background.x(), background.y(), background.z()};
  constexpr int64_t kChunk = 1 << 14;
  for (int64_t r0 = 0; r0 < total_rays; r0 += kChunk) {
    const int64_t nr = std::min(kChunk, total_rays - r0);
    SampleRays(rays.subspan(r0, nr), setup_.aabb, config_.RenderSamplerOptions(),
               occupancy ? occupancy : &occupancy_, 0, 0, executor, &ws.samples);
    RayMarch march;
    march.Start(ws.samples, 2);  // extras: the region mask M(x) and the warp's length ||D_final(x) - x||
    while (march.NextRound(ws.samples)) {
      const int64_t n = march.round_size();
      Fit(ws.positions, 3 * n);
      Fit(ws.dirs, 3 * n);
      ParallelFor(executor, march.active(), [&](int64_t k0, int64_t k1, int) {
        for (int64_t k = k0; k < k1; ++k) {
          const Vec3f& dir = rays[r0 + march.ray(k)].direction;
          for (int64_t i = march.round_begin(k); i < march.round_end(k); ++i) {
            const int64_t s = march.Sample(k, i);
            for (int a = 0; a < 3; ++a)
              ws.positions[3 * i + a] = ws.samples.positions[3 * s + a], ws.dirs[3 * i + a] = dir[a];
          }
        }
      });
      const float* positions = ws.positions.data();
      if (warp_ || traits_.entangled_beta) BroadcastExpression(beta, n, &ws.betas);
      Fit(ws.offsets, 3 * n);
      if (warp_) {
        warp_->Offsets(executor, n, positions, beta, ws.offsets.data(), &ws.warp_ws);
      } else {
        std::fill(ws.offsets.begin(), ws.offsets.end(), 0.f);
      }
      FieldForward(ws, n, positions, false, executor);
      Fit(ws.mask_values, n);
      Fit(ws.extras, 2 * n);
      ParallelFor(executor, n, [&](int64_t i0, int64_t i1, int) {
        mask_.EvaluateBatch(positions + 3 * i0, i1 - i0, ws.mask_values.data() + i0);
        for (int64_t i = i0; i < i1; ++i) {
          ws.extras[2 * i] = ws.mask_values[i];
          ws.extras[2 * i + 1] =
              Vec3f(ws.offsets[3 * i], ws.offsets[3 * i + 1], ws.offsets[3 * i + 2]).norm();
        }
      });
      march.Composite(ws.samples, ws.sigma.data(), ws.rgb.data(), ws.extras.data(),
                      static_cast<float>(config_.render.transmittance_eps), executor);
      out->samples_evaluated += n;
    }
    for (int64_t r = 0; r < nr; ++r) {
      const int64_t o = r0 + r;
      march.Color(r, bg, &out->color[3 * o]);
      out->depth[o] = march.depth(r);
      out->opacity[o] = march.opacity(r);
      out->mask[o] = march.extra(r, 0);
      out->deformation[o] = march.extra(r, 1);
    }
  }
}

void AvatarModel::UpdateOccupancy(uint64_t seed, int64_t step, const Executor& executor) {
  StaticFieldContext sctx;
  DeformationContext dctx;
  std::vector<float> betas, offsets, canonical, sigma;
  auto query = [&](const float* positions, int64_t n, float* out) {
    std::fill(out, out + n, 0.f);
    sigma.resize(n);
    if (warp_) offsets.resize(3 * n), canonical.resize(3 * n);
    for (const std::vector<float>& beta : setup_.training_expressions) {
      BroadcastExpression(beta, n, &betas);
      const float* c = positions;
      if (warp_) {
        warp_->ForwardTrain(executor, n, positions, betas.data(), offsets.data(), nullptr, &dctx, false);
        for (int64_t i = 0; i < 3 * n; ++i) canonical[i] = positions[i] + offsets[i];
        c = canonical.data();
      }
      static_field_->Density(executor, n, c, traits_.entangled_beta ? betas.data() : nullptr, sigma.data(),
                             &sctx);
      for (int64_t i = 0; i < n; ++i) out[i] = std::max(out[i], sigma[i]);
      if (!warp_ && !traits_.entangled_beta) break;  // density does not depend on beta
    }
  };
  occupancy_.Update(query, seed, step);
}

std::string AvatarModel::ToString() const {
  std::ostringstream os;
  os << "AvatarModel(method=" << MethodName(method_) << ", params=" << store_.size() << ", "
     << static_field_->ToString();
  if (warp_) os << ", " << warp_->ToString();
  os << ", mask from " << setup_.mask_source << ")";
  return os.str();
}

}  // namespace icef
