// One method of docs/design.md §2 = fields + renderer + losses. AvatarModel owns the parameter slab, the
// static canonical field, the deformation field (absent for `nerface`), the region mask M, the
// expression confidence and the occupancy grid, and provides the two things everything else needs:
//   - TrainForwardBackward: loss terms of a batch of training rays, gradients accumulated into the
//     slab (the trainer runs the optimiser);
//   - Render: colour, depth, opacity, expected mask and deformation magnitude of any rays at any
//     expression, with confidence-weighted warping D_final = P + kappa R_phi + (1 - kappa) R_lin
//     (field/deformation.h; P, the face-model prior, only for the *-prior methods).
#pragma once

#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "icef/core/parallel.h"
#include "icef/field/confidence.h"
#include "icef/field/deformation.h"
#include "icef/field/deformation_field.h"
#include "icef/field/prior_shading.h"
#include "icef/field/region_mask.h"
#include "icef/field/static_field.h"
#include "icef/field/symmetry_plane.h"
#include "icef/model/losses.h"
#include "icef/model/model_config.h"
#include "icef/model/model_setup.h"
#include "icef/nn/parameter_store.h"
#include "icef/render/compositing.h"
#include "icef/render/occupancy_grid.h"
#include "icef/render/ray_sampler.h"

namespace icef {

// Optimiser parameter groups of the slab.
inline constexpr int kGridGroup = 0;
inline constexpr int kMlpGroup = 1;
inline constexpr int kDeformGroup = 2;

struct RenderOutput {
  std::vector<float> color;        // [R, 3]
  std::vector<float> depth;        // [R] expected depth (0 where the ray hits nothing)
  std::vector<float> opacity;      // [R]
  std::vector<float> mask;         // [R] sum_i w_i M(x_i)
  std::vector<float> deformation;  // [R] sum_i w_i ||D_final(x_i) - x_i|| (world units)
  int64_t samples_evaluated = 0;   // field evaluations (samples behind opaque surfaces are skipped)
};

// Reusable buffers of TrainForwardBackward / Render (no allocation once grown).
struct ModelWorkspace;

class AvatarModel {
 public:
  // Builds the fields and registers their parameters. The *-prior methods take `prior` when given
  // (tests), else the face-model prior of setup.face_fit (model/face_prior.h). Errors: invalid
  // config or setup, a *-prior method without a face-model fit.
  static Result<std::unique_ptr<AvatarModel>> Create(const ModelConfig& config, const ModelSetup& setup,
                                                     const Executor& executor,
                                                     std::unique_ptr<DeformationPrior> prior = nullptr);
  ~AvatarModel();

  // Draws initial parameters (deterministic for the seed).
  void Initialize(uint64_t seed);

  // Forward + backward of one batch: every loss term (model/losses.h) with its weight and value,
  // and d total / d parameters accumulated into store().grads(). Only the samples that the pixel
  // rays composite (up to each ray's early termination) run the colour MLP and the prior shading's
  // normals: no term reads a colour elsewhere (the unseen views' rays carry a depth alone), unless
  // the symmetry prior's colour part (train.symmetry_colour) compares samples with their mirror
  // images, which then colours every sample.
  LossTerms TrainForwardBackward(const TrainRays& batch, const LossWeights& weights, uint64_t seed,
                                 int64_t step, const Executor& executor);
  // false: every training sample is coloured, as before the above (the same function; float sums in
  // another order). For tests and benchmarks.
  void set_color_composited_only(bool on) { color_composited_only_ = on; }
  // The last training step's buffers (tests).
  const ModelWorkspace& train_workspace() const { return *train_ws_; }

  // Renders rays at expression beta [expression_dim] over `background`. Samples are placed by
  // `occupancy` (null: the training grid occupancy(); RenderImage passes RenderOccupancy(beta)).
  // Rays march front to back in rounds and stop once opaque (render/ray_march.h): the fields are
  // evaluated only at samples that can still change the pixel, with the result of compositing
  // every sample.
  void Render(std::span<const Ray> rays, std::span<const float> beta, const Vec3f& background,
              const Executor& executor, RenderOutput* out, const OccupancyGrid* occupancy = nullptr) const;

  // The occupancy for rendering expression beta (docs/design.md §3): the training grid plus every cell
  // whose canonical point D_final(x, beta) holds density above the threshold inside the region the
  // visual hull allowed in training (the hull is looked up at the canonical point, through the
  // warp). Geometry a new expression moves outside the training silhouettes (an opened jaw) is
  // therefore not cut away, while space that training never constrained stays empty. nerface has
  // no canonical space: its density at (x, beta) is looked up with the hull at x.
  OccupancyGrid RenderOccupancy(std::span<const float> beta, const Executor& executor) const;

  // Folds the current density (max over the training expressions) into the occupancy grid.
  void UpdateOccupancy(uint64_t seed, int64_t step, const Executor& executor);

  // beta_n, delta, kappa for an expression.
  NearestExpression Nearest(std::span<const float> beta) const;

  // The face model's mouth cavity (the *-prior methods) and its learned colour (channel 0-2); the
  // teeth of an open mouth (priors with teeth: the ICT-FaceKit prior) and their learned colour.
  bool has_mouth_cavity() const { return cavity_block_ >= 0; }
  float CavityColour(int channel) const;
  bool has_teeth() const { return teeth_block_ >= 0; }
  float TeethColour(int channel) const;

  // Canonical-space query of the static field (tests and tools): sigma [n], rgb [n, 3].
  void QueryStatic(const Executor& executor, int64_t n, const float* canonical, const float* directions,
                   const float* condition, float* sigma, float* rgb) const;
  // The warp D_final(x, beta) - x, confidence-weighted as in Render: offsets [n, 3] world frame.
  void Offsets(const Executor& executor, int64_t n, const float* positions, std::span<const float> beta,
               float* offsets) const;
  // P + R_phi (kappa forced to 1) and P + R_lin around beta_n separately (tests).
  void OffsetsPhi(const Executor& executor, int64_t n, const float* positions, std::span<const float> beta,
                  float* offsets) const;
  void OffsetsLinearized(const Executor& executor, int64_t n, const float* positions,
                         std::span<const float> beta, float* offsets) const;

  nn::ParameterStore& store() { return store_; }
  const nn::ParameterStore& store() const { return store_; }
  const ModelConfig& config() const { return config_; }
  const ModelSetup& setup() const { return setup_; }
  Method method() const { return method_; }
  const MethodTraits& traits() const { return traits_; }
  OccupancyGrid& occupancy() { return occupancy_; }
  const OccupancyGrid& occupancy() const { return occupancy_; }
  const RegionMask& mask() const { return mask_; }
  const ExpressionConfidence& confidence() const { return confidence_; }
  // The face's symmetry plane (from the mask landmarks), or nullopt when they do not give one.
  const std::optional<SymmetryPlane>& symmetry_plane() const { return symmetry_; }
  StaticField& static_field() { return *static_field_; }
  // The learned residual R_phi (null for nerface), and the whole warp (null for nerface).
  DeformationField* residual_field() { return residual_field_.get(); }
  const DeformationField* residual_field() const { return residual_field_.get(); }
  const Deformation* warp() const { return warp_.get(); }
  // The light of the prior shading (field/prior_shading.h): a *-prior method with
  // model.prior_shading and a fitted light in the setup; else nullopt (no shading).
  const std::optional<Vec3f>& prior_light() const { return light_; }
  std::string ToString() const;

 private:
  AvatarModel(const ModelConfig& config, const ModelSetup& setup, RegionMask mask,
              ExpressionConfidence confidence);
  // Pieces of TrainForwardBackward / Render.
  // The training step's samples into ws.samples: the stratified sampler's, or (config importance)
  // those importance resampling draws from them by the current density (render/importance_sampler.h).
  void PlaceTrainingSamples(const TrainRays& batch, ModelWorkspace& ws, uint64_t seed, int64_t step,
                            const Executor& executor) const;
  void ExpandRays(const TrainRays& batch, ModelWorkspace& ws, const Executor& executor) const;
  // Static field (and the prior's shading and cavity) at n samples: canonical = positions +
  // ws.offsets; reads ws.dirs and ws.betas, writes ws.sigma and ws.rgb (and, when shaded, ws.shade and
  // in training ws.rgb_unshaded). color_rays >= 0: only the samples that the first color_rays rays
  // of ws.samples composite get a colour (ws.color_rows), the others rgb 0, unshaded; -1: all.
  void FieldForward(ModelWorkspace& ws, int64_t n, const float* positions, bool train,
                    const Executor& executor, int64_t color_rays = -1) const;
  // ws.color_rows: the samples of the first `rays` rays up to where compositing stops each ray
  // (CompositeRayUsed on the static field's densities, the cavity's where it is).
  void CompositedRows(ModelWorkspace& ws, int64_t rays, bool cavity) const;
  // The face model's normals at the samples `rows` (nullopt: all n) of FieldForward dense enough to
  // show (others: zero normals, no shading) into ws.normals_obs / normals_can; false when the prior
  // has none.
  bool ShadingNormals(ModelWorkspace& ws, int64_t n, std::optional<std::span<const int32_t>> rows,
                      const float* positions, const Executor& executor) const;
  // Runs the terms of one stage (model/losses.h) and records their values in `terms`.
  void RunLosses(LossStage stage, LossContext& ctx, LossTerms* terms);
  void WarpOffsets(const Executor& executor, int64_t n, const float* positions, std::span<const float> beta,
                   float* offsets, WarpPart part) const;

  ModelConfig config_;
  bool color_composited_only_ = true;
  ModelSetup setup_;
  Method method_;
  MethodTraits traits_;
  nn::ParameterStore store_;
  std::unique_ptr<StaticField> static_field_;
  std::unique_ptr<DeformationField> residual_field_;
  std::unique_ptr<DeformationPrior> prior_;
  std::unique_ptr<Deformation> warp_;
  std::optional<Vec3f> light_;
  int cavity_block_ = -1;  // the mouth cavity's colour logits (*-prior methods), else -1
  int teeth_block_ = -1;   // the teeth's colour logits (priors with teeth), else -1
  RegionMask mask_;
  ExpressionConfidence confidence_;
  OccupancyGrid occupancy_;
  std::optional<SymmetryPlane> symmetry_;
  std::unique_ptr<ModelWorkspace> train_ws_;
  mutable std::unique_ptr<ModelWorkspace> render_ws_;
  std::vector<std::unique_ptr<Loss>> losses_;  // every term of the objective, in evaluation order
  std::vector<Loss*> evaluated_losses_;        // those with a non-zero weight in the current batch
};

}  // namespace icef
