// The training objective as a list of loss terms (docs/design.md §2):
//   L = L_photo + lambda_mask L_mask + lambda_id L_id + lambda_smooth L_smooth
//       + lambda_distortion L_dist + lambda_occlusion L_occ + lambda_symmetry L_sym
//       + lambda_depth_prior L_depth.
// Each term is a small type behind one interface (name, weight, value, gradient). AvatarModel's
// training step runs them in stages along its backward pass, and everything that reports losses
// (the trainer's log, its NaN guard, the summary) loops over the list they produce.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "icef/core/parallel.h"
#include "icef/field/deformation.h"
#include "icef/field/deformation_field.h"
#include "icef/field/region_mask.h"
#include "icef/field/static_field.h"
#include "icef/field/symmetry_plane.h"
#include "icef/math/ray.h"
#include "icef/model/method.h"
#include "icef/model/model_setup.h"

namespace icef {

// Weights and settings of the terms. The lambdas default to 0 (term off): a run's weights come
// from TrainConfig::Losses(); the settings' defaults are TrainConfig's too. A term's Weight() zeroes
// it where the method or the batch has nothing for it to act on.
struct LossWeights {
  double lambda_id = 0.0;
  double lambda_id_prior = 0.0;  // L_id's weight for the methods on the face-model prior (L_id on R_phi)
  double lambda_smooth = 0.0;
  double lambda_mask = 0.0;
  double lambda_distortion = 0.0;
  double lambda_occlusion = 0.0;
  double lambda_occlusion_prior = 0.0;      // L_occ's weight for the methods on the face-model prior
  bool occlusion_prior_in_regions = false;  // there, L_occ inside the expression regions only (times M)
  double lambda_symmetry = 0.0;
  double lambda_depth_prior = 0.0;  // L_depth: rays with a face-model depth (TrainRays::depth_target)
  double depth_prior_window =
      0.0;  // L_depth's window half-width about t*, aabb diagonals (0: none; render/depth_loss.h)
  double depth_prior_reach = 0.0;  // L_depth's reach behind t*, aabb diagonals (0: none; render/depth_loss.h)
  double symmetry_colour = 0.0;    // weight of the colour part of L_sym (model/symmetry_loss.h)
  int symmetry_max_samples = 4096;  // cap on the samples mirrored by L_sym per batch
  double smooth_epsilon = 0.01;     // finite-difference offset of L_smooth, in half-extent units of the aabb
  int smooth_max_samples = 4096;    // cap on boundary samples used by L_smooth per batch
};

// One term's share of a batch's loss.
struct LossValue {
  std::string name;   // "photo", "mask", "id", "smooth", "distortion", "occlusion", "symmetry", "depth"
  double weight = 0;  // the weight it entered L with (0: not evaluated, value 0)
  double value = 0;   // the term itself (mean over the batch's rays or samples)
};

// The loss of one batch: every term of the objective, in evaluation order.
struct LossTerms {
  std::vector<LossValue> terms;
  double total = 0;     // sum of weight x value
  int64_t samples = 0;  // samples evaluated

  // The value of the named term (0 when the list has none).
  double Get(std::string_view name) const;
  double psnr() const;  // from the photo term (mean squared error)
  // The name of the first non-finite term ("total" for the sum), or "" when all are finite.
  std::string FirstNonFinite() const;
  bool AllFinite() const { return FirstNonFinite().empty(); }
  std::string ToString() const;
};

// A batch of training rays, each from a training frame with a known expression.
struct TrainRays {
  std::vector<Ray> rays;       // [R] world frame
  std::vector<int32_t> frame;  // [R] training frame index (its expression is setup.training_expressions[k])
  std::vector<float> target_rgb;    // [R, 3] composited over the background
  std::vector<float> target_alpha;  // [R] foreground mask, or empty when the images have no alpha
  std::vector<float> background;    // [R, 3] per-ray background the targets are composited over, or
                                    // empty for setup.background
  std::vector<float> depth_target;  // [R] ray parameter t where the fitted face model's surface is
                                    // hit (train.lambda_depth_prior), NaN where there is none; or empty
  // Rays [0, photo_rays) are pixels of the training images, with colour (and alpha) targets; the
  // rays after them look at the head from unseen views and carry a depth_target alone
  // (train.depth_prior_views): L_photo and L_mask skip them. -1: every ray is a pixel.
  int64_t photo_rays = -1;
  int64_t NumPhotoRays() const { return photo_rays < 0 ? int64_t(rays.size()) : photo_rays; }
};

struct ModelWorkspace;  // model/model_workspace.h

// What a term sees of the model and the batch during the training step.
struct LossContext {
  const TrainRays& batch;
  ModelWorkspace& ws;
  const LossWeights& weights;
  const ModelSetup& setup;
  const MethodTraits& traits;
  StaticField& static_field;
  DeformationField* residual_field;  // R_phi, or null (nerface; prior-only warps)
  const Deformation* warp;           // the whole warp, or null (nerface)
  const RegionMask& mask;
  const std::optional<SymmetryPlane>& symmetry;
  uint64_t seed;
  int64_t step;
  const Executor& executor;

  // M(x) at the batch's samples [n] (zero everywhere for the uniform-mask method); evaluated once
  // per batch, on first use.
  std::span<const float> RegionMaskValues();
  bool mask_values_ready = false;
};

// Where along the model's backward pass a term runs, and which gradient buffers of the workspace it
// adds to.
enum class LossStage {
  kRays,       // before compositing's backward: ws.d_color [R, 3], ws.d_opacity [R], ws.d_weights [n]
  kSamples,    // after it: ws.d_sigma [n], ws.d_rgb [n, 3]
  kCanonical,  // after the static field's backward: ws.d_canonical [n, 3], before the warp's backward
  kResidual,   // after the warp's backward: terms with passes of their own through R_phi
};

class Loss {
 public:
  virtual ~Loss() = default;
  virtual std::string_view name() const = 0;
  virtual LossStage stage() const = 0;
  // The weight the term enters L with for this batch and method (0: it is skipped).
  virtual double Weight(const LossContext& ctx) const = 0;
  // The term's value for the batch; adds weight x its gradient to the stage's buffers (and to the
  // parameter gradients of any pass of its own).
  virtual double Evaluate(LossContext& ctx, double weight) = 0;
  // Runs after the static field's backward pass (only when the term was evaluated in this batch),
  // for terms that must add to ws.d_canonical what their own static-field passes gave their
  // canonical positions.
  virtual void AfterStaticBackward(LossContext& /*ctx*/) {}
};

// Every term of the objective, in evaluation order (stage by stage).
std::vector<std::unique_ptr<Loss>> MakeLosses();

}  // namespace icef
