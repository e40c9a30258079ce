// Expression-region mask M(x) in [0, 1] (docs/design.md §2): 1 in the mouth, eye and brow regions, 0
// elsewhere, smooth in between. Built once from the 68 iBUG landmarks in the world frame:
//  - each region is a union of capsules (radius = the region's margin) around its landmark
//    polylines: brows 17-21 and 22-26 (open), eyes 36-41 and 42-47 (closed loops, filled by spokes
//    from the eye centre to every contour point), mouth 48-59 and 60-67 (closed loops, filled the
//    same way from the mouth centre);
//  - margins and softness are fractions of the inter-ocular distance (iod: distance between the
//    two eye centres), so the mask scales with the face, whatever the world units;
//  - region r has signed distance sd_r(x) = min over its capsules of |x - segment| - margin_r and
//    value m_r = 1 - smootherstep((sd_r + w) / 2w) with w = softness: exactly 1 for sd <= -w,
//    exactly 0 for sd >= w, C2 in between (compact support instead of a sigmoid, so M is exactly 0
//    away from the features and L_id is untouched there, and exactly 1 on the landmarks);
//  - M = 1 - prod_r (1 - m_r) (soft union).
// For speed M is tabulated once on a grid over the regions' bounding box (cell = grid_cell * iod)
// and evaluated by trilinear interpolation; outside that box M = 0 exactly (the box is padded
// beyond the support, so this is continuous).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "icef/core/parallel.h"
#include "icef/core/status.h"
#include "icef/data/dataset.h"
#include "icef/field/landmark_triangulation.h"
#include "icef/math/types.h"

namespace icef {

enum class FaceRegion { kBrows = 0, kEyes = 1, kMouth = 2 };
constexpr int kNumFaceRegions = 3;
const char* FaceRegionName(FaceRegion region);

struct RegionMaskOptions {
  bool brows = true;              // include the brow region (landmarks 17-26)
  bool eyes = true;               // include the eye region (landmarks 36-47)
  bool mouth = true;              // include the mouth region (landmarks 48-67)
  float brow_margin = 0.15f;      // capsule radius around the brow polylines, fraction of iod
  float eye_margin = 0.15f;       // capsule radius around the eye contours, fraction of iod
  float mouth_margin = 0.25f;     // capsule radius around the lip contours, fraction of iod
  float softness = 0.08f;         // half-width of the 1 -> 0 transition, fraction of iod (<= every margin)
  float grid_cell = 0.03f;        // cell size of the lookup grid, fraction of iod
  int max_grid_resolution = 256;  // cap on lookup-grid cells per axis

  bool operator==(const RegionMaskOptions&) const = default;
  Status Validate() const;
  std::string ToString() const;
};

class RegionMask {
 public:
  // From 68 world-frame landmarks. Errors: wrong count, non-finite values, zero inter-ocular
  // distance, invalid options.
  static Result<RegionMask> FromLandmarks(const std::vector<Vec3f>& landmarks,
                                          const RegionMaskOptions& options,
                                          const Executor& executor = Executor(1));

  // From a dataset's training frames: the mean of their landmarks_3d when every training frame
  // that has landmarks has them, else the landmarks triangulated from their landmarks_2d. Error
  // (naming the dataset) when the training frames carry neither.
  static Result<RegionMask> FromDataset(const Dataset& dataset, const RegionMaskOptions& options,
                                        const Executor& executor = Executor(1));

  // M at a world-frame point (grid lookup, trilinear).
  float Evaluate(const Vec3f& x) const;
  // M and dM/dx (gradient of the trilinear interpolant; zero outside the grid).
  float EvaluateWithGradient(const Vec3f& x, Vec3f* gradient) const;
  // Batched: positions [n, 3] world frame -> mask [n]; gradients [n, 3] when non-null.
  void EvaluateBatch(const float* positions, int64_t n, float* mask, float* gradients = nullptr) const;
  // M computed directly from the capsules (no grid); what the grid tabulates.
  float EvaluateExact(const Vec3f& x) const;
  // Value of one region (exact).
  float EvaluateRegionExact(FaceRegion region, const Vec3f& x) const;

  const std::vector<Vec3f>& landmarks() const { return landmarks_; }
  const RegionMaskOptions& options() const { return options_; }
  float inter_ocular_distance() const { return iod_; }
  Vec3f LandmarkCentroid() const;
  // Where the landmarks came from, e.g. "landmarks_3d (mean over 5 training frames)".
  const std::string& source() const { return source_; }
  // The lookup grid's box (world frame) and cells per axis.
  const Vec3f& grid_min() const { return grid_min_; }
  const Vec3i& grid_resolution() const { return grid_res_; }
  const Vec3f& grid_cell_size() const { return cell_; }

  std::string ToString() const;

 private:
  struct Segment {
    Vec3f a;
    Vec3f b;
    int region;
  };
  RegionMask() = default;
  void BuildGeometry();
  void BuildGrid(const Executor& executor);

  std::vector<Vec3f> landmarks_;
  RegionMaskOptions options_;
  std::string source_;
  float iod_ = 0;
  float margin_[kNumFaceRegions] = {0, 0, 0};  // world units
  bool enabled_[kNumFaceRegions] = {false, false, false};
  float softness_ = 0;  // world units
  std::vector<Segment> segments_;
  Vec3f support_min_[kNumFaceRegions];  // per region: box outside which m_r = 0
  Vec3f support_max_[kNumFaceRegions];
  Vec3f grid_min_ = Vec3f::Zero();
  Vec3f cell_ = Vec3f::Ones();      // world units per cell
  Vec3i grid_res_ = Vec3i::Zero();  // cells per axis; nodes = cells + 1
  std::vector<float> grid_;         // [(res.z+1), (res.y+1), (res.x+1)] node values
};

}  // namespace icef
