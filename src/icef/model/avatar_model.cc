#include "icef/model/avatar_model.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "icef/core/rng.h"
#include "icef/model/face_prior.h"
#include "icef/model/identity_losses.h"
#include "icef/model/symmetry_loss.h"
#include "icef/render/distortion_loss.h"
#include "icef/render/occlusion_loss.h"
#include "icef/render/ray_march.h"

namespace icef {

struct ModelWorkspace {
  RaySamples samples;
  std::vector<float> positions, dirs, betas, offsets, residual, canonical, sigma, rgb, d_sigma, d_rgb, d_canonical, mask_values, extras;
  std::vector<uint8_t> cavity;
  CompositeOutputs<float> composite;
  std::vector<float> d_color, d_opacity, d_weights;
  StaticFieldContext static_ctx;
  DeformationContext deform_ctx;
  DeformationWorkspace warp_ws;
  // L_smooth: 2m points (x_i, then x_i + delta_i).
  std::vector<float> smooth_positions, smooth_betas, smooth_offsets, smooth_d_offsets, smooth_weight;
  std::vector<int64_t> smooth_index;
  DeformationContext smooth_ctx;
  // L_sym: m samples (gathered) and their mirror images.
  std::vector<int64_t> sym_index;
  std::vector<float> sym_positions, sym_dirs, sym_sigma_a, sym_rgb_a, sym_sigma_b, sym_rgb_b, sym_dt;
  std::vector<float> sym_d_sigma_a, sym_d_rgb_a, sym_d_sigma_b, sym_d_rgb_b, sym_d_positions;
  StaticFieldContext sym_ctx;
};

namespace {
template <typename V>
void Fit(V& v, size_t size) {
  v.resize(size);
}

// The face model's open-mouth interior (DESIGN.md §2.1): an absorbing dark volume. Its density
// makes a cavity sample opaque within about a hundredth of the aabb; its colour is a dark red-brown
// mouth interior. Neither is learned: no training frame needs to show an open mouth.
constexpr float kCavityDensity = 400.f;
constexpr float kCavityColor[3] = {0.12f, 0.04f, 0.04f};

// Samples inside the cavity take its density and colour; their gradients are dropped (the static
// field did not produce them).
void ApplyCavity(int64_t n, const uint8_t* inside, float* sigma, float* rgb) {
  for (int64_t i = 0; i < n; ++i) {
    if (!inside[i]) continue;
    sigma[i] = kCavityDensity;
    for (int a = 0; a < 3; ++a) rgb[3 * i + a] = kCavityColor[a];
  }
}
void DropCavityGradients(int64_t n, const uint8_t* inside, float* d_sigma, float* d_rgb) {
  for (int64_t i = 0; i < n; ++i) {
    if (!inside[i]) continue;
    d_sigma[i] = 0.f;
    for (int a = 0; a < 3; ++a) d_rgb[3 * i + a] = 0.f;
  }
}
}  // namespace

double LossTerms::psnr() const { return photo > 0 ? -10.0 * std::log10(photo) : 99.0; }

bool LossTerms::AllFinite() const {
  return std::isfinite(photo) && std::isfinite(mask) && std::isfinite(id) && std::isfinite(smooth) &&
         std::isfinite(distortion) && std::isfinite(occlusion) && std::isfinite(symmetry) && std::isfinite(total);
}

std::string LossTerms::ToString() const {
  std::ostringstream os;
  os.precision(4);
  os << "loss " << total << " (photo " << photo << ", mask " << mask << ", id " << id << ", smooth " << smooth
     << ", dist " << distortion << ", occ " << occlusion << ", sym " << symmetry << ") psnr " << psnr();
  return os.str();
}

AvatarModel::AvatarModel(const ModelConfig& config, const ModelSetup& setup, RegionMask mask,
                     ExpressionConfidence confidence)
    : config_(config),
      setup_(setup),
      method_(config.ParsedMethod()),
      traits_(TraitsOf(method_)),
      mask_(std::move(mask)),
      confidence_(std::move(confidence)),
      occupancy_(setup.aabb, config.OccupancyOptions()),
      train_ws_(std::make_unique<ModelWorkspace>()),
      render_ws_(std::make_unique<ModelWorkspace>()) {}

AvatarModel::~AvatarModel() = default;

Result<std::unique_ptr<AvatarModel>> AvatarModel::Create(const ModelConfig& config, const ModelSetup& setup,
                                                     const Executor& executor,
                                                     std::unique_ptr<DeformationPrior> prior) {
  ICEF_RETURN_IF_ERROR(config.Validate().WithContext("model config"));
  if (!setup.aabb.IsValid()) return Status::Error("model setup: invalid aabb " + setup.aabb.ToString());
  if (setup.expression_dim < 1) return Status::Error("model setup: expression_dim must be >= 1");
  ICEF_ASSIGN_OR_RETURN(RegionMask mask, RegionMask::FromLandmarks(setup.mask_landmarks, config.MaskOptions(), executor));
  ICEF_ASSIGN_OR_RETURN(ExpressionConfidence confidence,
                        ExpressionConfidence::Create(setup.training_expressions, config.ConfidenceOpts()));
  if (confidence.expression_dim() != setup.expression_dim)
    return Status::Error("model setup: training expressions do not have expression_dim values");
  std::unique_ptr<AvatarModel> model(new AvatarModel(config, setup, std::move(mask), std::move(confidence)));
  if (Result<SymmetryPlane> plane = SymmetryPlane::FromLandmarks(setup.mask_landmarks); plane.ok())
    model->symmetry_ = *plane;
  model->static_field_ = std::make_unique<StaticField>(config.StaticOptions(setup.expression_dim), setup.aabb,
                                                       &model->store_, "static", kGridGroup, kMlpGroup);
  if (model->traits_.deformation) {
    model->residual_field_ = std::make_unique<DeformationField>(
        config.DeformationOptions(), setup.expression_dim, setup.aabb, &model->store_, "deformation", kDeformGroup);
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
  return model;
}

void AvatarModel::Initialize(uint64_t seed) {
  static_field_->Initialize(Mix64(seed ^ StreamId("static_field")));
  if (residual_field_) residual_field_->Initialize(Mix64(seed ^ StreamId("deformation_field")));
  occupancy_.Fill(true);
}

NearestExpression AvatarModel::Nearest(std::span<const float> beta) const { return confidence_.Nearest(beta); }

void AvatarModel::QueryStatic(const Executor& executor, int64_t n, const float* canonical, const float* directions,
                            const float* condition, float* sigma, float* rgb) const {
  StaticFieldContext ctx;
  static_field_->Forward(executor, n, canonical, directions, condition, sigma, rgb, &ctx, false, false);
}

void AvatarModel::WarpOffsets(const Executor& executor, int64_t n, const float* positions, std::span<const float> beta,
                              float* offsets, WarpPart part) const {
  ICEF_CHECK(static_cast<int>(beta.size()) == setup_.expression_dim, "beta has the wrong length");
  if (!warp_) {
    std::fill(offsets, offsets + 3 * n, 0.f);
    return;
  }
  DeformationWorkspace ws;
  warp_->Offsets(executor, n, positions, beta, offsets, &ws, part);
}

void AvatarModel::Offsets(const Executor& executor, int64_t n, const float* positions, std::span<const float> beta,
                        float* offsets) const {
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
                               const Executor& executor) const {
  const float* canonical = positions;
  if (warp_) {
    Fit(ws.canonical, 3 * n);
    for (int64_t i = 0; i < 3 * n; ++i) ws.canonical[i] = positions[i] + ws.offsets[i];
    canonical = ws.canonical.data();
  }
  Fit(ws.sigma, n);
  Fit(ws.rgb, 3 * n);
  static_field_->Forward(executor, n, canonical, ws.dirs.data(), traits_.entangled_beta ? ws.betas.data() : nullptr,
                         ws.sigma.data(), ws.rgb.data(), &ws.static_ctx, train, train && warp_ != nullptr);
  if (warp_ && warp_->has_prior()) {
    Fit(ws.cavity, n);
    warp_->Cavity(executor, n, positions, ws.betas.data(), ws.cavity.data());
    ApplyCavity(n, ws.cavity.data(), ws.sigma.data(), ws.rgb.data());
  }
}

double AvatarModel::PhotoAndMaskLoss(const TrainRays& batch, const LossWeights& weights, ModelWorkspace& ws,
                                     LossTerms* terms) const {
  const int64_t num_rays = static_cast<int64_t>(batch.rays.size());
  const bool has_alpha = !batch.target_alpha.empty() && weights.lambda_mask > 0;
  Fit(ws.d_color, 3 * num_rays);
  Fit(ws.d_opacity, num_rays);
  double photo = 0, mask_loss = 0;
  const double inv_c = 1.0 / (3.0 * std::max<int64_t>(num_rays, 1)), inv_r = 1.0 / std::max<int64_t>(num_rays, 1);
  for (int64_t r = 0; r < num_rays; ++r) {
    for (int a = 0; a < 3; ++a) {
      const double e = ws.composite.color[3 * r + a] - batch.target_rgb[3 * r + a];
      photo += e * e;
      ws.d_color[3 * r + a] = static_cast<float>(2.0 * e * inv_c);
    }
    ws.d_opacity[r] = 0.f;
    if (has_alpha) {
      const double e = ws.composite.opacity[r] - batch.target_alpha[r];
      mask_loss += e * e;
      ws.d_opacity[r] = static_cast<float>(weights.lambda_mask * 2.0 * e * inv_r);
    }
  }
  terms->photo = photo * inv_c;
  terms->mask = mask_loss * inv_r;
  return inv_r;
}

std::span<const float> AvatarModel::DistortionTerm(int64_t num_rays, const LossWeights& weights, ModelWorkspace& ws,
                                                   LossTerms* terms) const {
  if (weights.lambda_distortion <= 0) return {};
  // Distances in units of the aabb diagonal, so the weight does not depend on the scene's scale.
  const double inv_r = 1.0 / std::max<int64_t>(num_rays, 1), inv_diag = 1.0 / setup_.aabb.Extent().norm();
  Fit(ws.d_weights, ws.samples.size());
  double dist = 0;
  for (int64_t r = 0; r < num_rays; ++r) {
    const int64_t off = ws.samples.ray_offset[r], cnt = ws.samples.ray_count[r];
    if (cnt == 0) continue;
    dist += DistortionLossRay<float>(cnt, &ws.composite.weights[off], &ws.samples.t[off], &ws.samples.dt[off]);
    DistortionLossRayBackward<float>(cnt, &ws.composite.weights[off], &ws.samples.t[off], &ws.samples.dt[off],
                                     static_cast<float>(weights.lambda_distortion * inv_r * inv_diag),
                                     &ws.d_weights[off]);
  }
  terms->distortion = dist * inv_r * inv_diag;
  return ws.d_weights;
}

void AvatarModel::OcclusionTerm(int64_t num_rays, const LossWeights& weights, ModelWorkspace& ws,
                                LossTerms* terms) const {
  if (weights.lambda_occlusion <= 0) return;
  const double inv_r = 1.0 / std::max<int64_t>(num_rays, 1);
  double occ = 0;
  const float scale = static_cast<float>(weights.lambda_occlusion * inv_r);
  for (int64_t r = 0; r < num_rays; ++r) {
    const int64_t off = ws.samples.ray_offset[r], cnt = ws.samples.ray_count[r];
    occ += OcclusionLossRay<float>(static_cast<int>(cnt), &ws.composite.weights[off], &ws.sigma[off],
                                   &ws.samples.dt[off], scale, &ws.d_sigma[off]);
  }
  terms->occlusion = occ * inv_r;
}

LossTerms AvatarModel::TrainForwardBackward(const TrainRays& batch, const LossWeights& weights, uint64_t seed,
                                          int64_t step, const Executor& executor) {
  ModelWorkspace& ws = *train_ws_;
  const int64_t num_rays = static_cast<int64_t>(batch.rays.size());
  SampleRays(batch.rays, setup_.aabb, config_.SamplerOptions(true), &occupancy_, seed, step, executor, &ws.samples);
  const int64_t n = ws.samples.size();
  ExpandRays(batch, ws, executor);
  if (warp_) {  // observation -> canonical
    Fit(ws.offsets, 3 * n);
    Fit(ws.residual, 3 * n);
    warp_->ForwardTrain(executor, n, ws.samples.positions.data(), ws.betas.data(), ws.offsets.data(),
                        ws.residual.data(), &ws.deform_ctx, true);
  }
  FieldForward(ws, ws.samples.size(), ws.samples.positions.data(), true, executor);

  // Compositing over the known background.
  const float bg[3] = {setup_.background.x(), setup_.background.y(), setup_.background.z()};
  ICEF_CHECK(batch.background.empty() || int64_t(batch.background.size()) == 3 * num_rays, "background size");
  CompositeInputs<float> in{ws.sigma, ws.rgb, ws.samples.t, ws.samples.dt, ws.samples.ray_offset,
                            ws.samples.ray_count,
                            batch.background.empty() ? std::span<const float>(bg, 3) : std::span<const float>(batch.background)};
  CompositeForward(in, config_.CompositeOpts(), executor, &ws.composite);

  // Ray losses and their gradients, back through compositing to the samples.
  LossTerms terms;
  terms.samples = n;
  PhotoAndMaskLoss(batch, weights, ws, &terms);
  const std::span<const float> d_weights = DistortionTerm(num_rays, weights, ws, &terms);
  CompositeOutputGradients<float> grads{ws.d_color, ws.d_opacity, {}, d_weights};
  CompositeBackward(in, ws.composite, grads, executor, &ws.d_sigma, &ws.d_rgb);
  OcclusionTerm(num_rays, weights, ws, &terms);
  if (warp_ && warp_->has_prior()) DropCavityGradients(n, ws.cavity.data(), ws.d_sigma.data(), ws.d_rgb.data());

  // Mirroring acts in canonical space; nerface has none (its density depends on beta, and mirroring
  // it would penalise exactly its asymmetric expressions), so the prior does not apply to it.
  const bool symmetry = weights.lambda_symmetry > 0 && symmetry_ && !traits_.entangled_beta;
  const float* canonical = warp_ ? ws.canonical.data() : ws.samples.positions.data();
  if (symmetry) terms.symmetry = SymmetryTerm(ws, n, canonical, weights, executor);

  if (warp_) Fit(ws.d_canonical, 3 * n);
  static_field_->Backward(executor, n, ws.sigma.data(), ws.rgb.data(), ws.d_sigma.data(), ws.d_rgb.data(),
                          &ws.static_ctx, warp_ ? ws.d_canonical.data() : nullptr);
  if (symmetry && warp_) {
    // The mirror images P x_c move with the warp too: d/dx_c = H d/d(P x_c), H = I - 2 n n^T.
    for (size_t j = 0; j < ws.sym_index.size(); ++j) {
      const int64_t i = ws.sym_index[j];
      const Vec3f g = symmetry_->ReflectDirection(
          Vec3f(ws.sym_d_positions[3 * j], ws.sym_d_positions[3 * j + 1], ws.sym_d_positions[3 * j + 2]));
      for (int a = 0; a < 3; ++a) ws.d_canonical[3 * i + a] += g[a];
    }
  }
  if (warp_) IdentityTerms(weights, seed, step, ws, &terms, executor);
  const double lid = traits_.identity_losses ? weights.lambda_id : 0.0;
  const double lsm = traits_.identity_losses ? weights.lambda_smooth : 0.0;
  terms.total = terms.photo + weights.lambda_mask * terms.mask + lid * terms.id + lsm * terms.smooth +
                weights.lambda_distortion * terms.distortion + weights.lambda_occlusion * terms.occlusion +
                weights.lambda_symmetry * terms.symmetry;
  return terms;
}

void AvatarModel::IdentityTerms(const LossWeights& weights, uint64_t seed, int64_t step, ModelWorkspace& ws,
                                LossTerms* terms, const Executor& executor) {
  // L_id and L_smooth act on the learned residual R_phi only (DESIGN.md §2.1): what the face-model
  // prior knows is not penalised. Their gradients join d_canonical before R_phi's backward pass.
  const int64_t n = ws.samples.size();
  const bool id_terms = residual_field_ && traits_.identity_losses && (weights.lambda_id > 0 || weights.lambda_smooth > 0);
  if (id_terms) {
    Fit(ws.mask_values, n);
    if (traits_.uniform_mask) {
      std::fill(ws.mask_values.begin(), ws.mask_values.begin() + n, 0.f);
    } else {
      mask_.EvaluateBatch(ws.samples.positions.data(), n, ws.mask_values.data());
    }
  }
  if (id_terms && weights.lambda_id > 0) {
    const Vec3f half = 0.5f * setup_.aabb.Extent();
    const Vec3f inv_half2 = half.cwiseProduct(half).cwiseInverse();
    const float inv_half2_arr[3] = {inv_half2.x(), inv_half2.y(), inv_half2.z()};
    terms->id = IdentityLoss<float>(n, ws.residual.data(), ws.mask_values.data(), inv_half2_arr,
                                    static_cast<float>(weights.lambda_id), ws.d_canonical.data());
  }
  warp_->Backward(executor, n, ws.d_canonical.data(), &ws.deform_ctx);
  if (id_terms && weights.lambda_smooth > 0) terms->smooth = SmoothTerm(weights, seed, step, ws, executor);
}

double AvatarModel::SmoothTerm(const LossWeights& weights, uint64_t seed, int64_t step, ModelWorkspace& ws,
                               const Executor& executor) {
  // L_smooth (identity_losses.h) on up to smooth_max_samples boundary samples (w_b > 0).
  const int64_t n = ws.samples.size();
  const int b = setup_.expression_dim;
  const float* positions = ws.samples.positions.data();
  ws.smooth_index.clear();
  for (int64_t i = 0; i < n; ++i) {
    if (BoundaryWeight(ws.mask_values[i]) > 1e-3f) ws.smooth_index.push_back(i);
  }
  const int64_t avail = static_cast<int64_t>(ws.smooth_index.size());
  const int64_t m = std::min<int64_t>(avail, weights.smooth_max_samples);
  if (m <= 0) return 0.0;
  Fit(ws.smooth_positions, 6 * m);
  Fit(ws.smooth_betas, 2 * m * b);
  Fit(ws.smooth_offsets, 6 * m);
  Fit(ws.smooth_d_offsets, 6 * m);
  Fit(ws.smooth_weight, m);
  const Vec3f half = 0.5f * setup_.aabb.Extent();
  const float eps = static_cast<float>(weights.smooth_epsilon);
  for (int64_t j = 0; j < m; ++j) {
    const int64_t i = ws.smooth_index[j * avail / m];  // even stride over the boundary samples
    Rng rng(seed, StreamId("smooth_direction"), uint64_t(step), uint64_t(j));
    Vec3f u(static_cast<float>(rng.Normal()), static_cast<float>(rng.Normal()), static_cast<float>(rng.Normal()));
    u /= std::max(u.norm(), 1e-6f);
    for (int a = 0; a < 3; ++a) {
      ws.smooth_positions[3 * j + a] = positions[3 * i + a];
      ws.smooth_positions[3 * (m + j) + a] = positions[3 * i + a] + eps * u[a] * half[a];
    }
    std::copy(ws.betas.begin() + i * b, ws.betas.begin() + (i + 1) * b, ws.smooth_betas.begin() + j * b);
    std::copy(ws.betas.begin() + i * b, ws.betas.begin() + (i + 1) * b, ws.smooth_betas.begin() + (m + j) * b);
    ws.smooth_weight[j] = BoundaryWeight(ws.mask_values[i]);
  }
  residual_field_->Forward(executor, 2 * m, ws.smooth_positions.data(), ws.smooth_betas.data(),
                           ws.smooth_offsets.data(), &ws.smooth_ctx, true);
  const float half_arr[3] = {half.x(), half.y(), half.z()};
  const double loss = SmoothnessLoss<float>(m, ws.smooth_offsets.data(), ws.smooth_weight.data(), half_arr, eps,
                                            static_cast<float>(weights.lambda_smooth), ws.smooth_d_offsets.data());
  residual_field_->Backward(executor, 2 * m, ws.smooth_d_offsets.data(), &ws.smooth_ctx);
  return loss;
}

double AvatarModel::SymmetryTerm(ModelWorkspace& ws, int64_t n, const float* canonical, const LossWeights& weights,
                                 const Executor& executor) {
  // An even stride over the batch's samples; their canonical positions and directions mirrored.
  const int64_t m = std::min<int64_t>(n, weights.symmetry_max_samples);
  ws.sym_index.clear();
  if (m <= 0) return 0.0;
  Fit(ws.sym_index, m);
  Fit(ws.sym_positions, 3 * m);
  Fit(ws.sym_dirs, 3 * m);
  Fit(ws.sym_sigma_a, m);
  Fit(ws.sym_rgb_a, 3 * m);
  Fit(ws.sym_sigma_b, m);
  Fit(ws.sym_rgb_b, 3 * m);
  Fit(ws.sym_dt, m);
  Fit(ws.sym_d_sigma_a, m);
  Fit(ws.sym_d_rgb_a, 3 * m);
  Fit(ws.sym_d_sigma_b, m);
  Fit(ws.sym_d_rgb_b, 3 * m);
  for (int64_t j = 0; j < m; ++j) {
    const int64_t i = j * n / m;
    ws.sym_index[j] = i;
    const Vec3f x = symmetry_->ReflectPoint(Vec3f(canonical[3 * i], canonical[3 * i + 1], canonical[3 * i + 2]));
    const Vec3f d = symmetry_->ReflectDirection(Vec3f(ws.dirs[3 * i], ws.dirs[3 * i + 1], ws.dirs[3 * i + 2]));
    for (int a = 0; a < 3; ++a) {
      ws.sym_positions[3 * j + a] = x[a];
      ws.sym_dirs[3 * j + a] = d[a];
      ws.sym_rgb_a[3 * j + a] = ws.rgb[3 * i + a];
    }
    ws.sym_sigma_a[j] = ws.sigma[i];
    ws.sym_dt[j] = ws.samples.dt[i];
  }
  static_field_->Forward(executor, m, ws.sym_positions.data(), ws.sym_dirs.data(), nullptr,
                         ws.sym_sigma_b.data(), ws.sym_rgb_b.data(), &ws.sym_ctx, true, warp_ != nullptr);
  const float scale = static_cast<float>(weights.lambda_symmetry);
  const double loss = SymmetryLoss<float>(m, ws.sym_sigma_a.data(), ws.sym_rgb_a.data(), ws.sym_sigma_b.data(),
                                          ws.sym_rgb_b.data(), ws.sym_dt.data(),
                                          static_cast<float>(weights.symmetry_colour), scale, ws.sym_d_sigma_a.data(),
                                          ws.sym_d_rgb_a.data(), ws.sym_d_sigma_b.data(), ws.sym_d_rgb_b.data());
  // The original samples' share joins the main backward pass; the mirror images get their own.
  for (int64_t j = 0; j < m; ++j) {
    const int64_t i = ws.sym_index[j];
    ws.d_sigma[i] += ws.sym_d_sigma_a[j];
    for (int a = 0; a < 3; ++a) ws.d_rgb[3 * i + a] += ws.sym_d_rgb_a[3 * j + a];
  }
  if (warp_) Fit(ws.sym_d_positions, 3 * m);
  static_field_->Backward(executor, m, ws.sym_sigma_b.data(), ws.sym_rgb_b.data(), ws.sym_d_sigma_b.data(),
                          ws.sym_d_rgb_b.data(), &ws.sym_ctx, warp_ ? ws.sym_d_positions.data() : nullptr);
  return loss;
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
        if (cavity[i]) sigma[i] = kCavityDensity;
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
    SampleRays(rays.subspan(r0, nr), setup_.aabb, config_.SamplerOptions(false), occupancy ? occupancy : &occupancy_,
               0, 0, executor, &ws.samples);
    RayMarch march;
    march.Start(ws.samples, 2);  // extras: the region mask M(x) and the warp's length ||D_final(x) - x||
    while (march.NextRound(ws.samples)) {
      const int64_t n = march.round_size();
      Fit(ws.positions, 3 * n);
      Fit(ws.dirs, 3 * n);
      for (int64_t k = 0; k < march.active(); ++k) {
        const Vec3f& dir = rays[r0 + march.ray(k)].direction;
        for (int64_t i = march.round_begin(k); i < march.round_end(k); ++i) {
          const int64_t s = march.Sample(k, i);
          for (int a = 0; a < 3; ++a) ws.positions[3 * i + a] = ws.samples.positions[3 * s + a], ws.dirs[3 * i + a] = dir[a];
        }
      }
      const float* positions = ws.positions.data();
      if (warp_ || traits_.entangled_beta) BroadcastExpression(beta, n, &ws.betas);
      Fit(ws.offsets, 3 * n);
      std::fill(ws.offsets.begin(), ws.offsets.end(), 0.f);
      if (warp_) warp_->Offsets(executor, n, positions, beta, ws.offsets.data(), &ws.warp_ws);
      FieldForward(ws, n, positions, false, executor);
      Fit(ws.mask_values, n);
      mask_.EvaluateBatch(positions, n, ws.mask_values.data());
      Fit(ws.extras, 2 * n);
      for (int64_t i = 0; i < n; ++i) {
        ws.extras[2 * i] = ws.mask_values[i];
        ws.extras[2 * i + 1] = Vec3f(ws.offsets[3 * i], ws.offsets[3 * i + 1], ws.offsets[3 * i + 2]).norm();
      }
      march.Composite(ws.samples, ws.sigma.data(), ws.rgb.data(), ws.extras.data(),
                      static_cast<float>(config_.transmittance_eps), executor);
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
      static_field_->Density(executor, n, c, traits_.entangled_beta ? betas.data() : nullptr, sigma.data(), &sctx);
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
