#include "icef/field/region_mask.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

namespace icef {

const char* FaceRegionName(FaceRegion region) {
  switch (region) {
    case FaceRegion::kBrows:
      return "brows";
    case FaceRegion::kEyes:
      return "eyes";
    case FaceRegion::kMouth:
      return "mouth";
  }
  return "?";
}

Status RegionMaskOptions::Validate() const {
  auto positive = [](float v) { return std::isfinite(v) && v > 0.f; };
  if (!brows && !eyes && !mouth)
    return Status::Error("mask: at least one of brows, eyes, mouth must be enabled");
  if (!positive(brow_margin)) return Status::Error("mask.brow_margin must be > 0");
  if (!positive(eye_margin)) return Status::Error("mask.eye_margin must be > 0");
  if (!positive(mouth_margin)) return Status::Error("mask.mouth_margin must be > 0");
  if (!positive(softness)) return Status::Error("mask.softness must be > 0");
  if (softness > brow_margin || softness > eye_margin || softness > mouth_margin)
    return Status::Error("mask.softness must not exceed any margin (so that M = 1 on the landmarks)");
  if (!positive(grid_cell) || grid_cell > 0.5f) return Status::Error("mask.grid_cell must be in (0, 0.5]");
  if (max_grid_resolution < 4 || max_grid_resolution > 1024)
    return Status::Error("mask.max_grid_resolution must be in [4, 1024]");
  return Status::Ok();
}

std::string RegionMaskOptions::ToString() const {
  std::ostringstream os;
  os << "RegionMaskOptions(brows=" << brows << ", eyes=" << eyes << ", mouth=" << mouth
     << ", brow_margin=" << brow_margin << ", eye_margin=" << eye_margin << ", mouth_margin=" << mouth_margin
     << ", softness=" << softness << ", grid_cell=" << grid_cell
     << ", max_grid_resolution=" << max_grid_resolution << ")";
  return os.str();
}

namespace {

Vec3f Mean(const std::vector<Vec3f>& p, int begin, int end) {
  Vec3f s = Vec3f::Zero();
  for (int i = begin; i < end; ++i) s += p[i];
  return s / float(end - begin);
}

float SegmentDistanceSquared(const Vec3f& x, const Vec3f& a, const Vec3f& b) {
  const Vec3f ab = b - a;
  const float len2 = ab.squaredNorm();
  const float t = len2 > 0.f ? std::clamp((x - a).dot(ab) / len2, 0.f, 1.f) : 0.f;
  return (x - (a + t * ab)).squaredNorm();
}

// 1 for sd <= -w, 0 for sd >= w, quintic smootherstep in between.
float SoftInside(float sd, float w) {
  const float s = std::clamp((sd + w) / (2.f * w), 0.f, 1.f);
  return 1.f - s * s * s * (s * (6.f * s - 15.f) + 10.f);
}

}  // namespace

Result<RegionMask> RegionMask::FromLandmarks(const std::vector<Vec3f>& landmarks,
                                             const RegionMaskOptions& options, const Executor& executor) {
  ICEF_RETURN_IF_ERROR(options.Validate());
  if (int(landmarks.size()) != kNumLandmarks)
    return Status::Error("mask: expected " + std::to_string(kNumLandmarks) + " landmarks, got " +
                         std::to_string(landmarks.size()));
  for (int i = 0; i < kNumLandmarks; ++i)
    if (!landmarks[i].allFinite())
      return Status::Error("mask: landmark " + std::to_string(i) + " is not finite");
  RegionMask mask;
  mask.landmarks_ = landmarks;
  mask.options_ = options;
  mask.source_ = "landmarks";
  mask.iod_ = (Mean(landmarks, 36, 42) - Mean(landmarks, 42, 48)).norm();
  if (!(mask.iod_ > 1e-6f))
    return Status::Error("mask: inter-ocular distance is zero (eye landmarks coincide)");
  mask.BuildGeometry();
  mask.BuildGrid(executor);
  return mask;
}

Result<RegionMask> RegionMask::FromDataset(const Dataset& dataset, const RegionMaskOptions& options,
                                           const Executor& executor) {
  std::vector<Vec3f> mean(kNumLandmarks, Vec3f::Zero());
  int with_3d = 0, with_2d = 0;
  for (const Frame& f : dataset.train) {
    if (f.landmarks_2d) ++with_2d;
    if (!f.landmarks_3d) continue;
    if (int(f.landmarks_3d->size()) != kNumLandmarks)
      return Status::Error(dataset.root.string() + ": training frame " + f.file_path + ": landmarks_3d has " +
                           std::to_string(f.landmarks_3d->size()) + " points, expected 68");
    for (int i = 0; i < kNumLandmarks; ++i) mean[i] += (*f.landmarks_3d)[i];
    ++with_3d;
  }
  std::string source;
  if (with_3d > 0) {
    for (Vec3f& p : mean) p /= float(with_3d);
    source = "landmarks_3d (mean over " + std::to_string(with_3d) + " training frames)";
  } else if (with_2d > 0) {
    Result<TriangulatedLandmarks> tri = TriangulateLandmarks(dataset.train);
    if (!tri.ok())
      return tri.status().WithContext(dataset.root.string() +
                                      ": triangulating landmarks_2d of the training frames");
    mean = tri->points;
    std::ostringstream os;
    os << "triangulated from landmarks_2d of " << with_2d << " training views (mean reprojection rms "
       << tri->MeanRms() << " px)";
    source = os.str();
  } else {
    return Status::Error(dataset.root.string() +
                         ": the training frames have neither landmarks_3d nor landmarks_2d; the "
                         "expression-region mask needs landmarks (run `icef landmarks " +
                         dataset.root.string() + "` to detect them)");
  }
  Result<RegionMask> mask = FromLandmarks(mean, options, executor);
  if (!mask.ok()) return mask.status().WithContext(dataset.root.string());
  mask->source_ = source;
  return mask;
}

void RegionMask::BuildGeometry() {
  const float iod = iod_;
  enabled_[0] = options_.brows;
  enabled_[1] = options_.eyes;
  enabled_[2] = options_.mouth;
  margin_[0] = options_.brow_margin * iod;
  margin_[1] = options_.eye_margin * iod;
  margin_[2] = options_.mouth_margin * iod;
  softness_ = options_.softness * iod;
  const std::vector<Vec3f>& p = landmarks_;
  auto polyline = [&](int begin, int end, bool closed, int region) {
    for (int i = begin; i + 1 < end; ++i) segments_.push_back({p[i], p[i + 1], region});
    if (closed) segments_.push_back({p[end - 1], p[begin], region});
  };
  auto spokes = [&](int begin, int end, const Vec3f& centre, int region) {
    for (int i = begin; i < end; ++i) segments_.push_back({centre, p[i], region});
  };
  if (options_.brows) {
    polyline(17, 22, false, 0);
    polyline(22, 27, false, 0);
  }
  if (options_.eyes) {
    polyline(36, 42, true, 1);
    polyline(42, 48, true, 1);
    spokes(36, 42, Mean(p, 36, 42), 1);
    spokes(42, 48, Mean(p, 42, 48), 1);
  }
  if (options_.mouth) {
    polyline(48, 60, true, 2);
    polyline(60, 68, true, 2);
    spokes(48, 60, Mean(p, 48, 68), 2);
  }
  for (int r = 0; r < kNumFaceRegions; ++r) {
    support_min_[r] = Vec3f::Constant(std::numeric_limits<float>::infinity());
    support_max_[r] = -support_min_[r];
  }
  for (const Segment& s : segments_) {
    support_min_[s.region] = support_min_[s.region].cwiseMin(s.a).cwiseMin(s.b);
    support_max_[s.region] = support_max_[s.region].cwiseMax(s.a).cwiseMax(s.b);
  }
  for (int r = 0; r < kNumFaceRegions; ++r) {
    const float reach = margin_[r] + softness_;  // m_r = 0 beyond this distance
    support_min_[r] -= Vec3f::Constant(reach);
    support_max_[r] += Vec3f::Constant(reach);
  }
}

float RegionMask::EvaluateRegionExact(FaceRegion region, const Vec3f& x) const {
  const int r = int(region);
  if (!enabled_[r]) return 0.f;
  float d2 = std::numeric_limits<float>::infinity();
  for (const Segment& s : segments_)
    if (s.region == r) d2 = std::min(d2, SegmentDistanceSquared(x, s.a, s.b));
  return SoftInside(std::sqrt(d2) - margin_[r], softness_);
}

float RegionMask::EvaluateExact(const Vec3f& x) const {
  float outside = 1.f;
  for (int r = 0; r < kNumFaceRegions; ++r) {
    // Outside the region's support box the region contributes exactly 0.
    if (!enabled_[r] || (x.array() < support_min_[r].array()).any() ||
        (x.array() > support_max_[r].array()).any())
      continue;
    float d2 = std::numeric_limits<float>::infinity();
    for (const Segment& s : segments_)
      if (s.region == r) d2 = std::min(d2, SegmentDistanceSquared(x, s.a, s.b));
    outside *= 1.f - SoftInside(std::sqrt(d2) - margin_[r], softness_);
  }
  return 1.f - outside;
}

void RegionMask::BuildGrid(const Executor& executor) {
  Vec3f lo = Vec3f::Constant(std::numeric_limits<float>::infinity());
  Vec3f hi = -lo;
  for (const Segment& s : segments_) {
    lo = lo.cwiseMin(s.a).cwiseMin(s.b);
    hi = hi.cwiseMax(s.a).cwiseMax(s.b);
  }
  float max_margin = 0.f;
  for (int r = 0; r < kNumFaceRegions; ++r)
    if (enabled_[r]) max_margin = std::max(max_margin, margin_[r]);
  const float cell = options_.grid_cell * iod_;
  const float pad = max_margin + softness_ + 2.f * cell;  // M = 0 exactly beyond max_margin + softness
  lo -= Vec3f::Constant(pad);
  hi += Vec3f::Constant(pad);
  const Vec3f extent = hi - lo;
  for (int a = 0; a < 3; ++a) {
    grid_res_[a] = std::clamp(int(std::ceil(extent[a] / cell)), 2, options_.max_grid_resolution);
    cell_[a] = extent[a] / float(grid_res_[a]);
  }
  grid_min_ = lo;
  const int nx = grid_res_.x() + 1, ny = grid_res_.y() + 1, nz = grid_res_.z() + 1;
  grid_.assign(size_t(nx) * ny * nz, 0.f);
  ParallelForChunks(executor, nz, 1, [&](int64_t begin, int64_t end) {
    for (int64_t z = begin; z < end; ++z)
      for (int y = 0; y < ny; ++y)
        for (int x = 0; x < nx; ++x) {
          const Vec3f p = grid_min_ + Vec3f(float(x), float(y), float(z)).cwiseProduct(cell_);
          grid_[(size_t(z) * ny + y) * nx + x] = EvaluateExact(p);
        }
  });
}

float RegionMask::EvaluateWithGradient(const Vec3f& x, Vec3f* gradient) const {
  const Vec3f q = (x - grid_min_).cwiseQuotient(cell_);
  int i[3];
  float f[3];
  for (int a = 0; a < 3; ++a) {
    if (!(q[a] >= 0.f && q[a] <= float(grid_res_[a]))) {  // outside (or NaN): M = 0 there
      if (gradient) gradient->setZero();
      return 0.f;
    }
    i[a] = std::min(int(q[a]), grid_res_[a] - 1);
    f[a] = q[a] - float(i[a]);
  }
  const int nx = grid_res_.x() + 1, ny = grid_res_.y() + 1;
  auto at = [&](int dx, int dy, int dz) {
    return grid_[(size_t(i[2] + dz) * ny + (i[1] + dy)) * nx + (i[0] + dx)];
  };
  const float c000 = at(0, 0, 0), c100 = at(1, 0, 0), c010 = at(0, 1, 0), c110 = at(1, 1, 0);
  const float c001 = at(0, 0, 1), c101 = at(1, 0, 1), c011 = at(0, 1, 1), c111 = at(1, 1, 1);
  const float c00 = c000 + f[0] * (c100 - c000), c10 = c010 + f[0] * (c110 - c010);
  const float c01 = c001 + f[0] * (c101 - c001), c11 = c011 + f[0] * (c111 - c011);
  const float c0 = c00 + f[1] * (c10 - c00), c1 = c01 + f[1] * (c11 - c01);
  if (gradient) {
    const float dx0 = (1 - f[1]) * (c100 - c000) + f[1] * (c110 - c010);
    const float dx1 = (1 - f[1]) * (c101 - c001) + f[1] * (c111 - c011);
    (*gradient)[0] = ((1 - f[2]) * dx0 + f[2] * dx1) / cell_[0];
    (*gradient)[1] = ((1 - f[2]) * (c10 - c00) + f[2] * (c11 - c01)) / cell_[1];
    (*gradient)[2] = (c1 - c0) / cell_[2];
  }
  return std::clamp(c0 + f[2] * (c1 - c0), 0.f, 1.f);  // rounding can leave [0, 1] by ~1e-9
}

float RegionMask::Evaluate(const Vec3f& x) const { return EvaluateWithGradient(x, nullptr); }

void RegionMask::EvaluateBatch(const float* positions, int64_t n, float* mask, float* gradients) const {
  for (int64_t k = 0; k < n; ++k) {
    const Vec3f x(positions[3 * k], positions[3 * k + 1], positions[3 * k + 2]);
    if (gradients) {
      Vec3f g;
      mask[k] = EvaluateWithGradient(x, &g);
      for (int a = 0; a < 3; ++a) gradients[3 * k + a] = g[a];
    } else {
      mask[k] = EvaluateWithGradient(x, nullptr);
    }
  }
}

Vec3f RegionMask::LandmarkCentroid() const { return Mean(landmarks_, 0, kNumLandmarks); }

std::string RegionMask::ToString() const {
  std::ostringstream os;
  os << "RegionMask(source=" << source_ << ", iod=" << iod_ << ", grid=" << grid_res_.x() << "x"
     << grid_res_.y() << "x" << grid_res_.z() << ", " << options_.ToString() << ")";
  return os.str();
}

}  // namespace icef
