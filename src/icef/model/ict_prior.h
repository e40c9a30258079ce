// The ICT-FaceKit prior P of docs/design.md §2.1 as a DeformationPrior: the volumetric warp of the
// ICT mesh (face::IctWarp, head frame, cm) carried into the dataset's world frame,
//   P(x, beta) = S^-1 W(S x, beta),   S = head_from_world: x_head = scale * R * x_world + t,
// so offsets come back as R^T (W(S x) - S x) / scale. It is the ICT twin of FacePrior
// (face_prior.h), which does the same for the procedural face model.
//
// Expressions: a batch's betas [n, B] (B = 53, the model's expression order) hold few distinct rows
// (one per training frame plus render-time expressions). Each distinct row is posed once (~28 ms:
// the posed mesh and its KD-tree) and kept in a small least-recently-used cache; the rows of a batch
// that are not cached are posed in parallel. Negative and non-finite weights act as 0 (ARKit weights
// are 0..1), as in FacePrior. Every output depends only on its own point and (sanitised) row: not on
// the thread count, the batch's other samples or the order in which expressions were first seen.
//
// Mouth cavity (Cavity): the dark interior of an open mouth, behind the teeth and over the tongue.
// S x is in the cavity when (1) the expression parts the inner lips (their mean gap, iBUG 61-67,
// 62-66, 63-65, exceeds 0.3 cm; the neutral's is 0.1 cm, so at beta = 0 and every closed-mouth
// expression nothing is inside), (2) it lies in the posed mouth volume (the inside of ICT's
// mouth_socket bag and the lip triangles that join it to the face, closed by a fan over its rim about
// a centimetre behind the lips; inside = an odd count of crossings of a +z ray, found through a 2D
// grid with tie rules that make the surface watertight), and (3) its closest posed surface point
// is on mouth_socket or gums_tongue, on the side their normals point to (the air). Conservative:
// points nearest the lips or the teeth are never inside, so the cavity does not hide the teeth; the
// air just between the lips (in front of the rim) is the air rule's (below).
//
// Teeth (Cavity's kTeeth): when the expression parts the inner lips, S x lies inside the teeth when
// its closest posed surface point is on ICT's teeth, on the side their normals point away from. The
// training frames rarely show teeth, so the canonical field has none to warp (behind closed lips it
// holds whatever the lips left there); the avatar draws them as an opaque volume of one learned
// colour (AvatarModel::TeethColour).
//
// Air between parted lips (Cavity's kAir): the closest-point warp carries the space the lower lip
// left to where it was at rest (a point under the unmoving upper lip maps as far under it at rest,
// into the closed lips), so the canonical lips would fill the opening and hide what lies behind.
// When the lips are parted, a point within 1.5 cm of the inner lips' box that lies on the air side
// of its closest posed surface and whose canonical point lies more than 0.1 cm behind the surface at
// rest (on the side its normals point away from) is empty.
//
// Blinks: the warp's lid slide (ict_warp.h) comes first; offsets and normals are those of the slid
// point (the normals are not turned by the slide).
//
// Normals: from the closest point of S x on the posed surface (triangle t, barycentric b): observed =
// the posed mesh's interpolated vertex normal at (t, b), canonical = the neutral mesh's at (t, b),
// where the warp maps that point (within inner_radius P keeps the signed distance along it). Both
// are 0 where no surface lies within outer_radius, or where the warp's weight there has faded below
// 1e-3 (the last ~0.04 cm; the prior's shading is then neutral).
//
// Grid (IctPriorOptions::grid_cell): the closest-point search costs microseconds a point, and a
// training step asks it of every sample at a handful of expressions. Each posed expression therefore
// caches its offsets and both normals on a LazyGrid in the head frame (built brick by brick where
// points are asked), interpolated where the exact warp is smooth across a cell and exact elsewhere:
// between the lips, at the lids' margins, where the warp fades out. A cell whose points all lie
// smooth_beyond or more from the surface is interpolated whatever the tolerances: where two parts
// are equally close (inside the head, behind the lips) the exact warp jumps, and the prior there is
// the grid's smooth interpolation of it. Within smooth_beyond, offsets differ from the exact warp by
// about offset_tolerance (IctPrior.GridMatchesTheExactWarp: 99.9 % of points within 0.02 cm). The
// normals are stored times the warp's weight, so every channel fades to 0 at outer_radius and the
// cells around it interpolate as well. The offsets and the normals keep their tolerance tests apart (LazyGrid
// groups: Offsets interpolates where the offsets pass, whatever the normals), and a cell that fails
// is refined into grid_refine^3 fine cells the first time a point falls in it (LazyGrid::refine), so
// that the exact warp is asked only in the fine cells along a jump or a sharp bend. Measured on a real
// subject's 300-step training (smirk-dafoe, ICT K = 5, 2 threads): 0.68 s a step exact, 0.34 s with the grid,
// the same losses to four digits; on another host 0.49 s without smooth_beyond, 0.31 s with it. Cost: a grid
// over the whole head's box takes ~3.4 s to build on 2 threads and ~80 MB per expression (bricks are built
// only where points are asked); a refined cell ~4.6 KB more (grid_refine 4). BM_TrainStepIct against
// BM_TrainStep of the same run (this 2-core host): 318 against 125 ms a step (0.39x) before the groups and
// the refinement, 254 against 129 ms (0.51x) with them.
//
// Thread safety: const methods may be called concurrently (the cache is guarded by a mutex).
#pragma once

#include <cstdint>
#include <memory>
#include <mutex>
#include <span>
#include <string>
#include <vector>

#include "icef/core/status.h"
#include "icef/data/dataset.h"
#include "icef/face/face_fit.h"
#include "icef/face/ict_model.h"
#include "icef/face/ict_warp.h"
#include "icef/field/deformation_prior.h"
#include "icef/model/model_setup.h"

namespace icef {

class LazyGrid;

struct IctPriorOptions {
  face::IctWarpOptions warp;
  // cm: cell of the grid that caches each posed expression's warp and normals (LazyGrid: trilinear
  // where that reproduces the exact warp within the tolerances below, the exact warp elsewhere);
  // 0: always the exact warp.
  float grid_cell = 0.25f;
  float offset_tolerance = 0.01f;  // cm: a grid cell's largest offset error at its centre
  float normal_tolerance = 0.1f;   // a grid cell's largest normal error (per component) at its centre
  // cm: a grid cell whose points all lie at least this far from the surface is interpolated whatever
  // the tolerances: there the prior is the grid's smooth interpolation of the exact warp (which jumps
  // where two parts of the surface are equally close: inside the head, behind the lips; the rays'
  // density lies at the surface). Infinity: the tolerances everywhere.
  float smooth_beyond = 0.25f;
  // Fine cells per side of a grid cell that fails the tolerances (LazyGrid::Options::refine): the
  // exact warp is asked only in the fine cells that fail in turn. 0 or 1: not refined.
  int grid_refine = 4;

  Status Validate() const;
  std::string ToString() const;
};

class IctPrior final : public DeformationPrior {
 public:
  static constexpr int kCacheCapacity = 16;  // posed expressions kept between calls

  // model: shared, kept alive by the prior. identity: <= model.num_identities() coefficients.
  // head_from_world: dataset world frame -> ICT head frame (cm), e.g. FitIctHeadFromWorld.
  // Errors: invalid options, too many identity coefficients, a degenerate or non-finite similarity,
  // a model without the parts the warp and the mouth volume need.
  static Result<std::unique_ptr<IctPrior>> Create(std::shared_ptr<const face::IctModel> model,
                                                  std::span<const float> identity,
                                                  const face::Similarity& head_from_world,
                                                  const IctPriorOptions& options = {});
  ~IctPrior() override;
  IctPrior(const IctPrior&) = delete;
  IctPrior& operator=(const IctPrior&) = delete;

  // positions [n, 3] world frame, betas [n, 53] -> offsets [n, 3] world frame.
  void Offsets(const Executor& executor, int64_t n, const float* positions, const float* betas,
               float* offsets) const override;
  // positions [n, 3] world frame, betas [n, 53] -> inside [n] (the rules above).
  void Cavity(const Executor& executor, int64_t n, const float* positions, const float* betas,
              uint8_t* inside) const override;
  bool has_teeth() const override { return true; }
  // positions [n, 3] world frame, betas [n, 53] -> observed, canonical [n, 3] world frame, unit or 0.
  bool Normals(const Executor& executor, int64_t n, const float* positions, const float* betas,
               float* observed, float* canonical) const override;

  int expression_dims() const override;
  std::string ToString() const override;

  const face::IctWarp& warp() const { return *warp_; }
  const face::Similarity& head_from_world() const { return head_from_world_; }

  // Implementation types (ict_prior.cc): one posed expression (its warp, mouth volume and vertex
  // normals), and the mouth volume's closed surface as vertex indices (fixed for the model).
  struct Expression;
  struct MouthSurface;

 private:
  IctPrior() = default;

  // The posed expressions of the distinct (sanitised) rows of betas, in order of first appearance,
  // with their keys; poses the rows not in the cache (in parallel) and updates it.
  struct Batch {
    std::vector<std::vector<float>> keys;
    std::vector<std::shared_ptr<const Expression>> expressions;
  };
  Batch Prepare(const Executor& executor, int64_t n, const float* betas) const;
  // fn(i, expression, x_head) for every sample, in parallel over chunks of samples.
  template <class Fn>
  void ForEachSample(const Executor& executor, int64_t n, const float* positions, const float* betas,
                     Fn&& fn) const;
  std::shared_ptr<const Expression> Pose(const std::vector<float>& key) const;

  IctPriorOptions options_;
  std::shared_ptr<const face::IctModel> model_;
  std::unique_ptr<const face::IctWarp> warp_;  // heap-held: posed warps point to it
  std::unique_ptr<const MouthSurface> mouth_surface_;
  std::vector<float> identity_;
  face::Similarity head_from_world_;
  Mat3f head_from_world_linear_;    // scale * R
  Mat3f world_from_head_linear_;    // R^T / scale
  Mat3f world_from_head_rotation_;  // R^T (normals)
  Vec3f translation_;
  std::vector<Vec3f> neutral_normals_;      // of the warp surface at beta = 0, head frame
  std::shared_ptr<const Expression> rest_;  // beta = 0, always at hand

  struct CacheEntry {
    std::vector<float> key;
    std::shared_ptr<const Expression> expression;
    uint64_t last_used = 0;
  };
  mutable std::mutex mutex_;  // guards cache_ and clock_
  mutable std::vector<CacheEntry> cache_;
  mutable uint64_t clock_ = 0;
};

// The similarity head_from_world that maps the frames' world-frame 68 landmarks onto the model's
// neutral landmarks (of this identity), least squares over the landmarks that expressions move least:
// the nose (27-35) and the eye corners (36, 39, 42, 45) of every frame (Umeyama, with scale).
// landmarks_3d_world: per frame [68], world frame; frames may show different expressions.
// Non-finite landmarks are skipped. Errors: no frames, a frame without 68 landmarks, too few points.
Result<face::Similarity> FitIctHeadFromWorld(const face::IctModel& model, std::span<const float> identity,
                                             const std::vector<std::vector<Vec3f>>& landmarks_3d_world);

// True when the names are the model's expressions, in its order (a dataset `icef track --face-model
// ict` wrote).
bool IsIctExpressionSpace(const face::IctModel& model, const std::vector<std::string>& expression_names);

// ICT fitted to a dataset in its expression space: the identity from the training frames' 2D
// landmarks and intrinsics (face::FitIctToLandmarks with IctFitOptions::ForPhotos, each frame's pose
// and expression free), then
// head_from_world from their world-frame landmarks_3d (FitIctHeadFromWorld). Errors name the
// dataset: another expression space, training frames without both landmarks, a failed fit.
Result<IctFaceFit> FitIctToDataset(const face::IctModel& model, const Dataset& dataset);

}  // namespace icef
