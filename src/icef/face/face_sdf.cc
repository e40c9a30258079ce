// The head's signed distance: a smooth union of ellipsoids and cones (cranium, face, chin,
// cheeks, ears, neck, brow ridges, nose, lips), eye sockets with eyeballs and eyelid caps, and the
// mouth cavity carved in observation space.
#include <algorithm>
#include <array>
#include <cmath>
#include <sstream>

#include "icef/core/status.h"
#include "icef/face/face_model.h"
#include "icef/face/sdf_primitives.h"

namespace icef::face {

FaceModel::FaceModel(const ShapeParams& shape, const ExpressionStyle& style)
    : shape_(shape), style_(style), geometry_(FaceGeometry::FromShape(shape)) {
  const Status valid = style.Validate();
  ICEF_CHECK(valid.ok(), valid.message());
  jaw_hinge_ = geometry_.jaw_hinge + Vec3f(0.f, style.jaw_hinge_dy, style.jaw_hinge_dz);
  neutral_state_ = Prepare(std::vector<float>(kNumExpressions, 0.f));
  BuildNeutralLandmarks();
}

Aabb FaceModel::Bounds() const {
  Aabb box;
  box.min = Vec3f(-0.36f, -0.81f, -0.42f);
  box.max = Vec3f(0.36f, 0.45f, 0.45f);
  return box;
}

namespace {

// The smooth blend of cranium, face, chin and neck. The details protrude less than 0.07 from it.
[[gnu::always_inline]] inline float BaseDistance(const FaceGeometry& g, const Vec3f& p) {
  float d = SmoothMin(SdEllipsoid(p - g.cranium_c, g.cranium_r), SdEllipsoid(p - g.face_c, g.face_r), 0.07f);
  d = SmoothMin(d, SdEllipsoid(p - g.chin_c, g.chin_r), 0.05f);
  const float neck = std::max(SdCone(p, g.neck_a, g.neck_b, g.neck_r, g.neck_r), g.neck_cut_y - p.y());
  return SmoothMin(d, neck, 0.06f);
}

struct Detailed {
  float distance;  // the whole surface
  float skin;      // without the lids and eyeballs
  float lid;       // the nearer eye's two lid caps
  float eyeball;   // the nearer eyeball
  Vec3f q;         // p relative to the nearer eye's centre
};

// The lid caps' edge directions: the state's upper lids (per side) and the fixed lower lid.
struct LidEdges {
  float cos_upper[2], sin_upper[2], cos_lower, sin_lower;
  LidEdges(const FaceGeometry& g, const ExpressionState& s)
      : cos_upper{std::cos(s.lid_upper[0]), std::cos(s.lid_upper[1])},
        sin_upper{std::sin(s.lid_upper[0]), std::sin(s.lid_upper[1])},
        cos_lower(std::cos(g.lid_lower)),
        sin_lower(std::sin(g.lid_lower)) {}
};

// The base with cheeks, ears, brow ridges, nose and lips added and the nearer eye's socket, eyeball
// and lids. Branch-free (selects, not branches), so a loop over points vectorises.
[[gnu::always_inline]] inline Detailed AddDetails(const FaceGeometry& g, const LidEdges& lids, const Vec3f& p,
                                                  float base) {
  const float sx = std::abs(p.x());
  const Vec3f pm(sx, p.y(), p.z());  // mirrored to the left side for symmetric parts
  float d = SmoothMin(base, SdEllipsoid(pm - g.cheek_c[1], g.cheek_r), 0.05f);
  d = SmoothMin(d, SdEllipsoid(pm - g.ear_c[1], g.ear_r), 0.015f);
  d = SmoothMin(d, SdEllipsoid(pm - g.brow_ridge_c[1], g.brow_ridge_r), 0.03f);
  // Nose: bridge cone, tip, nostril wings.
  float nose = SdCone(p, g.nose_top, g.nose_tip, g.nose_top_r, g.nose_tip_r * 0.8f);
  nose = SmoothMin(nose, SdSphere(p - g.nose_tip, g.nose_tip_r), 0.015f);
  nose = SmoothMin(nose, SdEllipsoid(pm - g.nostril_c[1], g.nostril_r), 0.012f);
  d = SmoothMin(d, nose, 0.025f);
  // Lips.
  const float lips =
      std::min(SdEllipsoid(p - g.upper_lip_c, g.upper_lip_r), SdEllipsoid(p - g.lower_lip_c, g.lower_lip_r));
  d = SmoothMin(d, lips, 0.012f);
  // Eye socket of the nearer eye (the two sockets are far apart), then the eyeball and the lids.
  // The nearer side's values as a blend with weights 0 and 1 (exact), not a select between two
  // addresses, which does not vectorise.
  const float right = p.x() < 0.f ? 1.f : 0.f, left = 1.f - right;  // side 0, side 1
  const Vec3f q = p - (right * g.eye_c[0] + left * g.eye_c[1]);
  d = SmoothMax(d, -SdSphere(q - Vec3f(0.f, 0.f, 0.006f), g.eye_r + 0.009f), 0.012f);
  const float eyeball = SdSphere(q, g.eye_r);
  const float shell = Length(q) - (g.eye_r + g.lid_thickness);
  const float cos_up = right * lids.cos_upper[0] + left * lids.cos_upper[1];
  const float sin_up = right * lids.sin_upper[0] + left * lids.sin_upper[1];
  const float upper_lid = std::max(shell, -(q.y() * cos_up - q.z() * sin_up));
  const float lower_lid = std::max(shell, q.y() * lids.cos_lower - q.z() * lids.sin_lower);
  const float lid = std::min(upper_lid, lower_lid);
  Detailed out;
  out.skin = d;
  out.distance = std::min(SmoothMin(d, lid, 0.006f), eyeball);
  out.lid = lid;
  out.eyeball = eyeball;
  out.q = q;
  return out;
}

// Far from the face the details cannot be the closest part: the base, less their reach, bounds the
// distance (sphere tracing steps by it).
constexpr float kDetailReach = 0.12f, kDetailBound = 0.08f;

}  // namespace

float FaceModel::CanonicalDistance(const Vec3f& p, const ExpressionState& s, Material* material) const {
  const float base = BaseDistance(geometry_, p);
  if (base > kDetailReach && material == nullptr) return base - kDetailBound;
  const Detailed parts = AddDetails(geometry_, LidEdges(geometry_, s), p, base);
  if (material) {
    const float d = parts.distance;
    if (parts.eyeball <= d + 1e-6f && parts.eyeball < parts.lid - 1e-4f)
      *material = Material::kEyeball;
    else if (parts.lid < parts.skin && parts.lid < 0.01f && parts.q.norm() < geometry_.eye_r + 0.02f)
      *material = Material::kEyelid;
    else
      *material = Material::kSkin;
  }
  return parts.distance;
}

void FaceModel::CanonicalDistances(std::span<const Vec3f> points, const ExpressionState& s,
                                   float* distances) const {
  const FaceGeometry g = geometry_;  // a local copy: the stores to distances cannot alias it
  const LidEdges lids(g, s);
  // Every point pays for the details (no early exit), so that the loop over a chunk of points,
  // unpacked into coordinate arrays, vectorises; the result is CanonicalDistance's.
  constexpr size_t kChunk = 64;
  alignas(64) float xs[kChunk], ys[kChunk], zs[kChunk], out[kChunk];
  for (size_t c0 = 0; c0 < points.size(); c0 += kChunk) {
    const size_t m = std::min(kChunk, points.size() - c0);
    for (size_t i = 0; i < m; ++i)
      xs[i] = points[c0 + i].x(), ys[i] = points[c0 + i].y(), zs[i] = points[c0 + i].z();
    for (size_t i = 0; i < m; ++i) {
      const Vec3f p(xs[i], ys[i], zs[i]);
      const float base = BaseDistance(g, p);
      const float d = AddDetails(g, lids, p, base).distance;
      out[i] = base > kDetailReach ? base - kDetailBound : d;
    }
    std::copy(out, out + m, distances + c0);
  }
}

void FaceModel::CanonicalNormals(std::span<const Vec3f> points, const ExpressionState& s,
                                 Vec3f* normals) const {
  // Normal()'s tetrahedron of four distances, in batches of points.
  constexpr int64_t kBatch = 256;
  const float h = kNormalStep;
  const Vec3f k[4] = {Vec3f(1.f, -1.f, -1.f), Vec3f(-1.f, -1.f, 1.f), Vec3f(-1.f, 1.f, -1.f),
                      Vec3f(1.f, 1.f, 1.f)};
  std::array<Vec3f, 4 * kBatch> probes;
  std::array<float, 4 * kBatch> distances;
  for (size_t b0 = 0; b0 < points.size(); b0 += kBatch) {
    const int64_t m = std::min<int64_t>(kBatch, int64_t(points.size() - b0));
    for (int64_t i = 0; i < m; ++i)
      for (int c = 0; c < 4; ++c) probes[4 * i + c] = points[b0 + i] + h * k[c];
    CanonicalDistances(std::span<const Vec3f>(probes.data(), size_t(4 * m)), s, distances.data());
    for (int64_t i = 0; i < m; ++i) {
      const float* d = distances.data() + 4 * i;
      const Vec3f n = k[0] * d[0] + k[1] * d[1] + k[2] * d[2] + k[3] * d[3];
      const float len = n.norm();
      normals[b0 + i] = len > 0.f ? Vec3f(n / len) : Vec3f::UnitZ();
    }
  }
}

float FaceModel::Distance(const Vec3f& x, const ExpressionState& s) const {
  const Vec3f x_c = Warp(x, s);
  float d = CanonicalDistance(x_c, s, nullptr);
  if (s.cavity) d = SmoothMax(d, -SdEllipsoid(x - s.cavity_c, s.cavity_r), 0.004f);
  return d;
}

FaceModel::Sample FaceModel::Evaluate(const Vec3f& x, const ExpressionState& s) const {
  Sample out;
  out.canonical = Warp(x, s);
  out.material = Material::kSkin;
  out.distance = CanonicalDistance(out.canonical, s, &out.material);
  if (s.cavity) {
    const float carve = -SdEllipsoid(x - s.cavity_c, s.cavity_r);
    if (carve > out.distance - 0.002f) out.material = Material::kMouthCavity;
    out.distance = SmoothMax(out.distance, carve, 0.004f);
  }
  return out;
}

Vec3f FaceModel::Normal(const Vec3f& x, const ExpressionState& s) const {
  const float h = kNormalStep;
  const Vec3f k0(1.f, -1.f, -1.f), k1(-1.f, -1.f, 1.f), k2(-1.f, 1.f, -1.f), k3(1.f, 1.f, 1.f);
  const Vec3f n = k0 * Distance(x + h * k0, s) + k1 * Distance(x + h * k1, s) + k2 * Distance(x + h * k2, s) +
                  k3 * Distance(x + h * k3, s);
  const float len = n.norm();
  return len > 0.f ? Vec3f(n / len) : Vec3f::UnitZ();
}

float FaceModel::Trace(const Ray& ray, float t_near, float t_far, const ExpressionState& s, int max_steps,
                       float epsilon) const {
  float t = t_near;
  for (int i = 0; i < max_steps && t <= t_far; ++i) {
    const float d = Distance(ray.At(t), s);
    if (d < epsilon) return t;
    t += std::max(d * s.step_scale, 0.5f * epsilon);
  }
  return -1.f;
}

std::string FaceModel::ToString() const {
  return "FaceModel(" + shape_.ToString() + ", " + style_.ToString() + ")";
}

}  // namespace icef::face
