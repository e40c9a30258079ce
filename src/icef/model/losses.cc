#include "icef/model/losses.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "icef/core/rng.h"
#include "icef/model/identity_losses.h"
#include "icef/model/model_workspace.h"
#include "icef/model/symmetry_loss.h"
#include "icef/render/depth_loss.h"
#include "icef/render/distortion_loss.h"
#include "icef/render/occlusion_loss.h"

namespace icef {

double LossTerms::Get(std::string_view name) const {
  for (const LossValue& t : terms)
    if (t.name == name) return t.value;
  return 0.0;
}

double LossTerms::psnr() const {
  const double photo = Get("photo");
  return photo > 0 ? -10.0 * std::log10(photo) : 99.0;
}

std::string LossTerms::FirstNonFinite() const {
  for (const LossValue& t : terms)
    if (!std::isfinite(t.value)) return t.name;
  return std::isfinite(total) ? "" : "total";
}

std::string LossTerms::ToString() const {
  std::ostringstream os;
  os.precision(4);
  os << "loss " << total << " (";
  for (size_t i = 0; i < terms.size(); ++i) os << (i ? ", " : "") << terms[i].name << " " << terms[i].value;
  os << ") psnr " << psnr();
  return os.str();
}

std::span<const float> LossContext::RegionMaskValues() {
  const int64_t n = ws.samples.size();
  if (!mask_values_ready) {
    Fit(ws.mask_values, n);
    if (traits.uniform_mask) {
      std::fill(ws.mask_values.begin(), ws.mask_values.begin() + n, 0.f);
    } else {
      const float* positions = ws.samples.positions.data();
      ParallelFor(executor, n, [&](int64_t i0, int64_t i1, int) {
        mask.EvaluateBatch(positions + 3 * i0, i1 - i0, ws.mask_values.data() + i0);
      });
    }
    mask_values_ready = true;
  }
  return {ws.mask_values.data(), static_cast<size_t>(n)};
}

namespace {

double InvRays(const LossContext& ctx) { return 1.0 / std::max<size_t>(ctx.batch.rays.size(), 1); }

// L_photo: mean squared error of the composited colour over the pixel rays and channels.
class PhotoTerm final : public Loss {
 public:
  std::string_view name() const override { return "photo"; }
  LossStage stage() const override { return LossStage::kRays; }
  double Weight(const LossContext&) const override { return 1.0; }
  double Evaluate(LossContext& ctx, double weight) override {
    ModelWorkspace& ws = ctx.ws;
    const int64_t num_rays = ctx.batch.NumPhotoRays();
    const double inv_c = 1.0 / std::max<int64_t>(num_rays, 1) / 3.0;
    double photo = 0;
    for (int64_t i = 0; i < 3 * num_rays; ++i) {
      const double e = ws.composite.color[i] - ctx.batch.target_rgb[i];
      photo += e * e;
      ws.d_color[i] += static_cast<float>(weight * 2.0 * e * inv_c);
    }
    return photo * inv_c;
  }
};

// L_mask: mean squared error of the opacity against the images' alpha over the pixel rays (images
// with alpha only).
class MaskTerm final : public Loss {
 public:
  std::string_view name() const override { return "mask"; }
  LossStage stage() const override { return LossStage::kRays; }
  double Weight(const LossContext& ctx) const override {
    return ctx.batch.target_alpha.empty() ? 0.0 : ctx.weights.lambda_mask;
  }
  double Evaluate(LossContext& ctx, double weight) override {
    ModelWorkspace& ws = ctx.ws;
    const int64_t num_rays = ctx.batch.NumPhotoRays();
    const double inv_r = 1.0 / std::max<int64_t>(num_rays, 1);
    double loss = 0;
    for (int64_t r = 0; r < num_rays; ++r) {
      const double e = ws.composite.opacity[r] - ctx.batch.target_alpha[r];
      loss += e * e;
      ws.d_opacity[r] += static_cast<float>(weight * 2.0 * e * inv_r);
    }
    return loss * inv_r;
  }
};

// L_dist: mip-NeRF 360's distortion loss per ray (render/distortion_loss.h), distances in units of
// the aabb diagonal so the weight does not depend on the scene's scale.
class DistortionTerm final : public Loss {
 public:
  std::string_view name() const override { return "distortion"; }
  LossStage stage() const override { return LossStage::kRays; }
  double Weight(const LossContext& ctx) const override { return ctx.weights.lambda_distortion; }
  double Evaluate(LossContext& ctx, double weight) override {
    ModelWorkspace& ws = ctx.ws;
    const int64_t num_rays = static_cast<int64_t>(ctx.batch.rays.size());
    const double inv_r = InvRays(ctx), inv_diag = 1.0 / ctx.setup.aabb.Extent().norm();
    Fit(ws.d_weights, ws.samples.size());  // the first term on the sample weights: it overwrites them
    double dist = 0;
    for (int64_t r = 0; r < num_rays; ++r) {
      const int64_t off = ws.samples.ray_offset[r], cnt = ws.samples.ray_count[r];
      if (cnt == 0) continue;
      dist +=
          DistortionLossRay<float>(cnt, &ws.composite.weights[off], &ws.samples.t[off], &ws.samples.dt[off]);
      DistortionLossRayBackward<float>(cnt, &ws.composite.weights[off], &ws.samples.t[off],
                                       &ws.samples.dt[off], static_cast<float>(weight * inv_r * inv_diag),
                                       &ws.d_weights[off]);
    }
    return dist * inv_r * inv_diag;
  }
};

// L_depth: a ray's compositing-weighted depth against the fitted face model's depth on it
// (TrainRays::depth_target, NaN = none; render/depth_loss.h), distances in aabb diagonals:
//   E_r = sum_i w_i (t_i - t*_r) / diag,   L_depth = mean over the batch's rays of E_r^2
// (rays without a target count 0). The first moment only: opacity is left to L_photo and L_mask.
class DepthPriorTerm final : public Loss {
 public:
  std::string_view name() const override { return "depth"; }
  LossStage stage() const override { return LossStage::kRays; }
  double Weight(const LossContext& ctx) const override {
    return ctx.batch.depth_target.empty() ? 0.0 : ctx.weights.lambda_depth_prior;
  }
  double Evaluate(LossContext& ctx, double weight) override {
    ModelWorkspace& ws = ctx.ws;
    const int64_t num_rays = static_cast<int64_t>(ctx.batch.rays.size());
    ICEF_CHECK(int64_t(ctx.batch.depth_target.size()) == num_rays, "depth_target size");
    const double inv_r = InvRays(ctx), inv_diag = 1.0 / ctx.setup.aabb.Extent().norm();
    if (ws.d_weights.size() != ws.samples.size()) ws.d_weights.assign(ws.samples.size(), 0.f);
    const float scale = static_cast<float>(weight * inv_r * inv_diag * inv_diag);
    const DepthWindow<float> shape{static_cast<float>(ctx.weights.depth_prior_window / inv_diag),
                                   static_cast<float>(ctx.weights.depth_prior_reach / inv_diag)};
    double loss = 0;
    for (int64_t r = 0; r < num_rays; ++r) {
      const float target = ctx.batch.depth_target[r];
      const int64_t off = ws.samples.ray_offset[r], cnt = ws.samples.ray_count[r];
      if (!std::isfinite(target) || cnt == 0) continue;
      loss += DepthMomentLossRay<float>(static_cast<int>(cnt), &ws.composite.weights[off], &ws.samples.t[off],
                                        target, shape, scale, &ws.d_weights[off]) *
              inv_diag * inv_diag;
    }
    return loss * inv_r;
  }
};

// L_occ: the occlusion sparsity prior per ray (render/occlusion_loss.h), under a weight of its own on
// the face-model prior (train.lambda_occlusion_prior), where it may act inside the expression
// regions alone (train.occlusion_prior_in_regions: each sample's term times the region mask M).
class OcclusionTerm final : public Loss {
 public:
  std::string_view name() const override { return "occlusion"; }
  LossStage stage() const override { return LossStage::kSamples; }
  double Weight(const LossContext& ctx) const override {
    return ctx.traits.prior ? ctx.weights.lambda_occlusion_prior : ctx.weights.lambda_occlusion;
  }
  double Evaluate(LossContext& ctx, double weight) override {
    ModelWorkspace& ws = ctx.ws;
    const int64_t num_rays = static_cast<int64_t>(ctx.batch.rays.size());
    const double inv_r = InvRays(ctx);
    const float scale = static_cast<float>(weight * inv_r);
    const float* region =
        ctx.traits.prior && ctx.weights.occlusion_prior_in_regions ? ctx.RegionMaskValues().data() : nullptr;
    double occ = 0;
    for (int64_t r = 0; r < num_rays; ++r) {
      const int64_t off = ws.samples.ray_offset[r], cnt = ws.samples.ray_count[r];
      occ += OcclusionLossRay<float>(static_cast<int>(cnt), &ws.composite.weights[off], &ws.sigma[off],
                                     &ws.samples.dt[off], scale, &ws.d_sigma[off],
                                     region ? region + off : nullptr);
    }
    return occ * inv_r;
  }
};

// L_sym (model/symmetry_loss.h): the static field against its own mirror image across the face's
// symmetry plane, at an even stride of the batch's canonical samples. Mirroring acts in canonical
// space; nerface has none (its density depends on beta, and mirroring it would penalise exactly
// its asymmetric expressions), so the prior does not apply to it.
class SymmetryTerm final : public Loss {
 public:
  std::string_view name() const override { return "symmetry"; }
  LossStage stage() const override { return LossStage::kSamples; }
  double Weight(const LossContext& ctx) const override {
    return ctx.symmetry && !ctx.traits.entangled_beta ? ctx.weights.lambda_symmetry : 0.0;
  }
  double Evaluate(LossContext& ctx, double weight) override;
  // The mirror images P x_c move with the warp too: d/dx_c += H d/d(P x_c), H = I - 2 n n^T.
  void AfterStaticBackward(LossContext& ctx) override {
    ModelWorkspace& ws = ctx.ws;
    if (!ctx.warp) return;
    for (size_t j = 0; j < ws.sym_index.size(); ++j) {
      const int64_t i = ws.sym_index[j];
      const Vec3f g = ctx.symmetry->ReflectDirection(
          Vec3f(ws.sym_d_positions[3 * j], ws.sym_d_positions[3 * j + 1], ws.sym_d_positions[3 * j + 2]));
      for (int a = 0; a < 3; ++a) ws.d_canonical[3 * i + a] += g[a];
    }
  }
};

double SymmetryTerm::Evaluate(LossContext& ctx, double weight) {
  ModelWorkspace& ws = ctx.ws;
  const int64_t n = ws.samples.size();
  const float* canonical = ctx.warp ? ws.canonical.data() : ws.samples.positions.data();
  const int64_t m = std::min<int64_t>(n, ctx.weights.symmetry_max_samples);
  ws.sym_index.clear();
  if (m <= 0) return 0.0;
  Fit(ws.sym_index, m);
  for (auto* v :
       {&ws.sym_positions, &ws.sym_dirs, &ws.sym_rgb_a, &ws.sym_rgb_b, &ws.sym_d_rgb_a, &ws.sym_d_rgb_b})
    Fit(*v, 3 * m);
  for (auto* v : {&ws.sym_sigma_a, &ws.sym_sigma_b, &ws.sym_dt, &ws.sym_d_sigma_a, &ws.sym_d_sigma_b})
    Fit(*v, m);
  const SymmetryPlane& plane = *ctx.symmetry;
  for (int64_t j = 0; j < m; ++j) {
    const int64_t i = j * n / m;
    ws.sym_index[j] = i;
    const Vec3f x = plane.ReflectPoint(Vec3f(canonical[3 * i], canonical[3 * i + 1], canonical[3 * i + 2]));
    const Vec3f d = plane.ReflectDirection(Vec3f(ws.dirs[3 * i], ws.dirs[3 * i + 1], ws.dirs[3 * i + 2]));
    for (int a = 0; a < 3; ++a) {
      ws.sym_positions[3 * j + a] = x[a];
      ws.sym_dirs[3 * j + a] = d[a];
      ws.sym_rgb_a[3 * j + a] = ws.rgb[3 * i + a];
    }
    ws.sym_sigma_a[j] = ws.sigma[i];
    ws.sym_dt[j] = ws.samples.dt[i];
  }
  const bool warp = ctx.warp != nullptr;
  ctx.static_field.Forward(ctx.executor, m, ws.sym_positions.data(), ws.sym_dirs.data(), nullptr,
                           ws.sym_sigma_b.data(), ws.sym_rgb_b.data(), &ws.sym_ctx, true, warp);
  const double loss = SymmetryLoss<float>(
      m, ws.sym_sigma_a.data(), ws.sym_rgb_a.data(), ws.sym_sigma_b.data(), ws.sym_rgb_b.data(),
      ws.sym_dt.data(), static_cast<float>(ctx.weights.symmetry_colour), static_cast<float>(weight),
      ws.sym_d_sigma_a.data(), ws.sym_d_rgb_a.data(), ws.sym_d_sigma_b.data(), ws.sym_d_rgb_b.data());
  // The original samples' share joins the main backward pass; the mirror images get their own.
  for (int64_t j = 0; j < m; ++j) {
    const int64_t i = ws.sym_index[j];
    ws.d_sigma[i] += ws.sym_d_sigma_a[j];
    for (int a = 0; a < 3; ++a) ws.d_rgb[3 * i + a] += ws.sym_d_rgb_a[3 * j + a];
  }
  if (warp) Fit(ws.sym_d_positions, 3 * m);
  ctx.static_field.Backward(ctx.executor, m, ws.sym_sigma_b.data(), ws.sym_rgb_b.data(),
                            ws.sym_d_sigma_b.data(), ws.sym_d_rgb_b.data(), &ws.sym_ctx,
                            warp ? ws.sym_d_positions.data() : nullptr);
  return loss;
}

// L_id and L_smooth (model/identity_losses.h) act on the learned residual R_phi only (docs/design.md
// §2.1): what the face-model prior knows is not penalised.
double IdentityWeight(const LossContext& ctx, double lambda) {
  return ctx.residual_field && ctx.traits.identity_losses ? lambda : 0.0;
}

// L_id: its gradient joins d_canonical before the warp's backward pass (the residual is part of
// the offsets, d offsets / d residual = I).
class IdTerm final : public Loss {
 public:
  std::string_view name() const override { return "id"; }
  LossStage stage() const override { return LossStage::kCanonical; }
  // On the face-model prior L_id penalises the residual alone, a smaller quantity than icef's whole
  // deformation, under a weight of its own (train.lambda_id_prior).
  double Weight(const LossContext& ctx) const override {
    return IdentityWeight(ctx, ctx.traits.prior ? ctx.weights.lambda_id_prior : ctx.weights.lambda_id);
  }
  double Evaluate(LossContext& ctx, double weight) override {
    ModelWorkspace& ws = ctx.ws;
    const std::span<const float> mask = ctx.RegionMaskValues();
    const Vec3f half = 0.5f * ctx.setup.aabb.Extent();
    const Vec3f inv_half2 = half.cwiseProduct(half).cwiseInverse();
    const float inv_half2_arr[3] = {inv_half2.x(), inv_half2.y(), inv_half2.z()};
    return IdentityLoss<float>(ws.samples.size(), ws.residual.data(), mask.data(), inv_half2_arr,
                               static_cast<float>(weight), ws.d_canonical.data());
  }
};

// L_smooth on up to smooth_max_samples boundary samples (w_b > 0), with a pass of its own through
// R_phi at pairs of points a finite difference apart.
class SmoothTerm final : public Loss {
 public:
  std::string_view name() const override { return "smooth"; }
  LossStage stage() const override { return LossStage::kResidual; }
  double Weight(const LossContext& ctx) const override {
    return IdentityWeight(ctx, ctx.weights.lambda_smooth);
  }
  double Evaluate(LossContext& ctx, double weight) override;
};

double SmoothTerm::Evaluate(LossContext& ctx, double weight) {
  ModelWorkspace& ws = ctx.ws;
  const std::span<const float> mask = ctx.RegionMaskValues();
  const int64_t n = ws.samples.size();
  const int b = ctx.setup.expression_dim;
  const float* positions = ws.samples.positions.data();
  ws.smooth_index.clear();
  for (int64_t i = 0; i < n; ++i)
    if (BoundaryWeight(mask[i]) > 1e-3f) ws.smooth_index.push_back(i);
  const int64_t avail = static_cast<int64_t>(ws.smooth_index.size());
  const int64_t m = std::min<int64_t>(avail, ctx.weights.smooth_max_samples);
  if (m <= 0) return 0.0;
  for (auto* v : {&ws.smooth_positions, &ws.smooth_offsets, &ws.smooth_d_offsets}) Fit(*v, 6 * m);
  Fit(ws.smooth_betas, 2 * m * b);
  Fit(ws.smooth_weight, m);
  const Vec3f half = 0.5f * ctx.setup.aabb.Extent();
  const float eps = static_cast<float>(ctx.weights.smooth_epsilon);
  for (int64_t j = 0; j < m; ++j) {
    const int64_t i = ws.smooth_index[j * avail / m];  // even stride over the boundary samples
    Rng rng(ctx.seed, StreamId("smooth_direction"), uint64_t(ctx.step), uint64_t(j));
    Vec3f u(static_cast<float>(rng.Normal()), static_cast<float>(rng.Normal()),
            static_cast<float>(rng.Normal()));
    u /= std::max(u.norm(), 1e-6f);
    for (int a = 0; a < 3; ++a) {
      ws.smooth_positions[3 * j + a] = positions[3 * i + a];
      ws.smooth_positions[3 * (m + j) + a] = positions[3 * i + a] + eps * u[a] * half[a];
    }
    std::copy(ws.betas.begin() + i * b, ws.betas.begin() + (i + 1) * b, ws.smooth_betas.begin() + j * b);
    std::copy(ws.betas.begin() + i * b, ws.betas.begin() + (i + 1) * b,
              ws.smooth_betas.begin() + (m + j) * b);
    ws.smooth_weight[j] = BoundaryWeight(mask[i]);
  }
  DeformationField& field = *ctx.residual_field;
  field.Forward(ctx.executor, 2 * m, ws.smooth_positions.data(), ws.smooth_betas.data(),
                ws.smooth_offsets.data(), &ws.smooth_ctx, true);
  const float half_arr[3] = {half.x(), half.y(), half.z()};
  const double loss = SmoothnessLoss<float>(m, ws.smooth_offsets.data(), ws.smooth_weight.data(), half_arr,
                                            eps, static_cast<float>(weight), ws.smooth_d_offsets.data());
  field.Backward(ctx.executor, 2 * m, ws.smooth_d_offsets.data(), &ws.smooth_ctx);
  return loss;
}

}  // namespace

std::vector<std::unique_ptr<Loss>> MakeLosses() {
  std::vector<std::unique_ptr<Loss>> losses;
  losses.push_back(std::make_unique<PhotoTerm>());
  losses.push_back(std::make_unique<MaskTerm>());
  losses.push_back(std::make_unique<DistortionTerm>());
  losses.push_back(std::make_unique<DepthPriorTerm>());  // after DistortionTerm, which overwrites d_weights
  losses.push_back(std::make_unique<OcclusionTerm>());
  losses.push_back(std::make_unique<SymmetryTerm>());
  losses.push_back(std::make_unique<IdTerm>());
  losses.push_back(std::make_unique<SmoothTerm>());
  return losses;
}

}  // namespace icef
