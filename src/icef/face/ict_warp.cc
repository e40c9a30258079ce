#include "icef/face/ict_warp.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <nanoflann.hpp>
#include <sstream>
#include <string_view>

namespace icef::face {

namespace {

// The parts of the warp's surface (ict_warp.h says why these).
constexpr std::string_view kSurfaceParts[] = {
    "face",  "head_neck",   "mouth_socket", "eye_socket_left", "eye_socket_right", "gums_tongue",
    "teeth", "sclera_left", "iris_left",    "sclera_right",    "iris_right"};

// The eyes of the lid slide (ict_warp.h): their scleras, and the parts that are not skin.
constexpr std::string_view kScleras[2] = {"sclera_left", "sclera_right"};
constexpr std::string_view kBlinks[2] = {"eyeBlink_L", "eyeBlink_R"};
constexpr std::string_view kEyeballParts[] = {"sclera_left", "iris_left", "sclera_right", "iris_right"};
constexpr float kLidTop = 1.5707963f;   // elevation straight up: the slide ends there
constexpr float kOpeningReach = 3.f;    // cm: skin this far in front (+z) covers the eyeball
constexpr float kOpeningStep = 0.025f;  // rad: elevations tried per column
constexpr float kOpeningLimit = 1.4f;   // rad: elevations tried, -limit..limit
// rad: the slide covers the opening grown by this above and below: a real subject's eye, which the
// fitted identity's lids only approximate, extends past the mesh's opening (the validation video's
// fitted eyelid landmarks lie 0.02-0.05 rad outside it, and its avatar kept iris showing at
// eyeBlink = 1 with no margin).
constexpr float kLidMargin = 0.15f;

// Most KD-tree points per triangle edge (a triangle gets at most kMaxSubdivisions^2).
constexpr int kMaxSubdivisions = 64;

using Corners = std::array<Vec3f, 3>;

Corners TriangleCorners(const std::vector<Vec3f>& mesh, const std::array<uint32_t, 3>& t) {
  return {mesh[t[0]], mesh[t[1]], mesh[t[2]]};
}

Vec3f AtBarycentric(const Corners& c, const Vec3f& b) { return b[0] * c[0] + b[1] * c[1] + b[2] * c[2]; }

// The farthest corner's distance from the centroid: every point of the triangle is this close to it.
float CentroidRadius(const Corners& c) {
  const Vec3f centroid = (c[0] + c[1] + c[2]) / 3.f;
  return std::max({(c[0] - centroid).norm(), (c[1] - centroid).norm(), (c[2] - centroid).norm()});
}

// Barycentric coordinates of the point of triangle c closest to p (Ericson, Real-Time Collision
// Detection, 5.1.5: Voronoi regions of the corners, then of the edges, else the interior).
Vec3f ClosestBarycentric(const Vec3f& p, const Corners& c) {
  const Vec3f ab = c[1] - c[0], ac = c[2] - c[0], ap = p - c[0];
  const float d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return {1, 0, 0};
  const Vec3f bp = p - c[1];
  const float d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return {0, 1, 0};
  const float vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) {
    const float v = d1 / (d1 - d3);
    return {1 - v, v, 0};
  }
  const Vec3f cp = p - c[2];
  const float d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return {0, 0, 1};
  const float vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) {
    const float w = d2 / (d2 - d6);
    return {1 - w, 0, w};
  }
  const float va = d3 * d6 - d5 * d4;
  if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0) {
    const float w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    return {0, 1 - w, w};
  }
  const float sum = va + vb + vc;
  if (!(sum > 0)) {  // degenerate (no area): the nearest corner
    const float e[3] = {ap.squaredNorm(), bp.squaredNorm(), cp.squaredNorm()};
    const int k = static_cast<int>(std::min_element(e, e + 3) - e);
    return Vec3f::Unit(k);
  }
  const float v = vb / sum, w = vc / sum;
  return {1 - v - w, v, w};
}

// Distance along the ray o + t d (t > 0) to triangle c, or infinity (Moller-Trumbore).
float RayTriangle(const Vec3f& o, const Vec3f& d, const Corners& c) {
  const Vec3f e1 = c[1] - c[0], e2 = c[2] - c[0], p = d.cross(e2);
  const float det = e1.dot(p);
  if (std::abs(det) < 1e-12f) return std::numeric_limits<float>::infinity();
  const Vec3f s = o - c[0];
  const float u = s.dot(p) / det;
  if (u < 0.f || u > 1.f) return std::numeric_limits<float>::infinity();
  const Vec3f q = s.cross(e1);
  const float v = d.dot(q) / det;
  if (v < 0.f || u + v > 1.f) return std::numeric_limits<float>::infinity();
  const float t = e2.dot(q) / det;
  return t > 0.f ? t : std::numeric_limits<float>::infinity();
}

// Hermite smoothstep: 0 at or below e0, 1 at or above e1.
float SmoothStep(float e0, float e1, float x) {
  const float t = std::clamp((x - e0) / (e1 - e0), 0.f, 1.f);
  return t * t * (3.f - 2.f * t);
}

// One eye of the lid slide on the neutral: the sclera's sphere (least-squares centre, median
// radius) and the rest opening by column (ict_warp.h). skin: the surface triangles that cover it.
IctEye MeasureEye(const std::vector<Vec3f>& neutral, const std::vector<uint8_t>& labels, int sclera,
                  const std::vector<std::array<uint32_t, 3>>& skin) {
  IctEye eye;
  // |p|^2 = 2 c . p + k, least squares over the sclera's vertices.
  std::vector<Vec3f> points;
  for (size_t v = 0; v < neutral.size(); ++v)
    if (labels[v] == sclera) points.push_back(neutral[v]);
  Eigen::MatrixXd a(points.size(), 4);
  Eigen::VectorXd b(points.size());
  for (size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector3d p = points[i].cast<double>();
    a.row(static_cast<Eigen::Index>(i)) << 2 * p.x(), 2 * p.y(), 2 * p.z(), 1;
    b[static_cast<Eigen::Index>(i)] = p.squaredNorm();
  }
  eye.centre = a.colPivHouseholderQr().solve(b).head<3>().cast<float>();
  std::vector<float> radii;
  for (const Vec3f& p : points) radii.push_back((p - eye.centre).norm());
  std::nth_element(radii.begin(), radii.begin() + radii.size() / 2, radii.end());
  eye.radius = radii[radii.size() / 2];
  std::vector<Corners> near;  // skin within reach of the eyeball
  for (const auto& t : skin) {
    const Corners c = TriangleCorners(neutral, t);
    if (std::any_of(c.begin(), c.end(),
                    [&](const Vec3f& p) { return (p - eye.centre).norm() < eye.radius + kOpeningReach; }))
      near.push_back(c);
  }
  for (int k = 0; k < IctEye::kColumns; ++k) {
    const float u = -1.f + (static_cast<float>(k) + 0.5f) * 2.f / IctEye::kColumns,
                across = std::sqrt(1.f - u * u);
    float lower = INFINITY, upper = -INFINITY;
    for (float theta = -kOpeningLimit; theta <= kOpeningLimit; theta += kOpeningStep) {
      const Vec3f d(u, across * std::sin(theta), across * std::cos(theta));
      const Vec3f o = eye.centre + eye.radius * d;
      const bool covered = std::any_of(near.begin(), near.end(), [&](const Corners& c) {
        return RayTriangle(o, Vec3f::UnitZ(), c) <= kOpeningReach;
      });
      if (!covered) lower = std::min(lower, theta), upper = std::max(upper, theta);
    }
    if (lower > upper) lower = upper = 0.f;  // no opening
    eye.lower[k] = lower, eye.upper[k] = upper;
  }
  return eye;
}

// An orthonormal frame of a triangle (first edge, in-plane perpendicular, face normal) and the
// in-plane coordinates of its two edges from corner 0 (columns); false when degenerate.
bool TriangleFrame(const Corners& c, Mat3f* frame, Eigen::Matrix2f* edges) {
  const Vec3f e1 = c[1] - c[0], e2 = c[2] - c[0], n = e1.cross(e2);
  const float l1 = e1.norm(), ln = n.norm();
  if (!(l1 > 0 && ln > 0)) return false;
  const Vec3f t1 = e1 / l1, nn = n / ln, t2 = nn.cross(t1);
  frame->col(0) = t1;
  frame->col(1) = t2;
  frame->col(2) = nn;
  *edges << l1, e2.dot(t1), 0, e2.dot(t2);
  return true;
}

// The rotation carrying triangle `from` onto `to` as a quaternion (x, y, z, w), w >= 0: face normal
// onto face normal and, in the plane, the rotation part (polar decomposition) of the triangle's 2D
// affine map. The identity, exactly, when the triangles are equal or either is degenerate.
Vec4f TriangleRotation(const Corners& from, const Corners& to) {
  const Vec4f identity(0, 0, 0, 1);
  Mat3f frame_from, frame_to;
  Eigen::Matrix2f edges_from, edges_to;
  if (from == to || !TriangleFrame(from, &frame_from, &edges_from) ||
      !TriangleFrame(to, &frame_to, &edges_to))
    return identity;
  const Eigen::Matrix2f a = edges_to * edges_from.inverse();
  const float angle = std::atan2(a(1, 0) - a(0, 1), a(0, 0) + a(1, 1));
  Mat3f in_plane = Mat3f::Identity();
  in_plane.topLeftCorner<2, 2>() << std::cos(angle), -std::sin(angle), std::sin(angle), std::cos(angle);
  const Vec4f q = Eigen::Quaternionf(Mat3f(frame_to * in_plane * frame_from.transpose())).coeffs();
  return q[3] < 0 ? Vec4f(-q) : q;
}

// The rotation of a sum of same-hemisphere quaternions: normalised, and the identity exactly when the
// sum has no vector part (a sum of identities).
Mat3f RotationOfSum(const Vec4f& q) {
  if (q.head<3>() == Vec3f::Zero()) return Mat3f::Identity();
  const Vec4f n = q.normalized();
  return Eigen::Quaternionf(n[3], n[0], n[1], n[2]).toRotationMatrix();
}

}  // namespace

std::pair<float, float> IctEye::Opening(float u) const {
  const float s = std::clamp((u + 1.f) * kColumns / 2.f - 0.5f, 0.f, kColumns - 1.f);
  const int k = std::min(static_cast<int>(s), kColumns - 2);
  const float f = s - static_cast<float>(k);
  return {(1.f - f) * lower[k] + f * lower[k + 1], (1.f - f) * upper[k] + f * upper[k + 1]};
}

Vec3f IctEye::Slide(const Vec3f& x, float blink) const {
  const Vec3f q = x - centre;
  if (!(blink > 0.f) || q.z() <= 0.f) return x;
  const float r = q.norm(), u = q.x() / radius;
  const float weight = SmoothStep(-0.6f, -0.3f, r - radius) * (1.f - SmoothStep(0.4f, 0.9f, r - radius));
  if (weight <= 0.f || !(std::abs(u) < 1.f)) return x;
  const auto [open_lower, open_upper] = Opening(u);
  // The opening grown by the margin (less where the opening is lower than that, so that the slide
  // fades out with the opening at the eye's corners).
  const float margin = std::min(kLidMargin, open_upper - open_lower);
  const float upper = open_upper + margin, lower = open_lower - margin;
  const float edge = upper - std::min(blink, 1.f) * (upper - lower);
  const float theta = std::atan2(q.y(), q.z());
  if (!(edge < upper) || theta < edge || theta > kLidTop) return x;
  const float mapped = upper + (theta - edge) * (kLidTop - upper) / (kLidTop - edge);
  const float a = weight * (mapped - theta), c = std::cos(a), sn = std::sin(a);
  // Rotation about the x axis through the centre raising the elevation by a.
  return centre + Vec3f(q.x(), q.y() * c + q.z() * sn, -q.y() * sn + q.z() * c);
}

float IctWarpOptions::Weight(float distance) const {
  if (distance <= inner_radius) return 1.f;
  if (distance >= outer_radius) return 0.f;
  const float s = (outer_radius - distance) / (outer_radius - inner_radius);
  return s * s * (3.f - 2.f * s);
}

Status IctWarpOptions::Validate() const {
  if (!std::isfinite(inner_radius) || !(inner_radius >= 0))
    return Status::Error("inner_radius must be a finite number >= 0 (cm), got " +
                         std::to_string(inner_radius));
  if (!std::isfinite(outer_radius) || !(outer_radius > inner_radius))
    return Status::Error("outer_radius must be a finite number > inner_radius (cm), got " +
                         std::to_string(outer_radius));
  if (!std::isfinite(tree_point_spacing) || !(tree_point_spacing >= 0.01f))
    return Status::Error("tree_point_spacing must be a finite number >= 0.01 (cm), got " +
                         std::to_string(tree_point_spacing));
  return Status::Ok();
}

std::string IctWarpOptions::ToString() const {
  std::ostringstream os;
  os << "IctWarpOptions(inner_radius=" << inner_radius << ", outer_radius=" << outer_radius
     << ", tree_point_spacing=" << tree_point_spacing << ")";
  return os.str();
}

std::string IctWarpClosest::ToString() const {
  std::ostringstream os;
  os << "IctWarpClosest(triangle=" << triangle << ", barycentric=[" << barycentric[0] << ", "
     << barycentric[1] << ", " << barycentric[2] << "], distance=" << distance << ")";
  return os.str();
}

// ---------------------------------------------------------------------------------------------------------
// IctWarp

Result<IctWarp> IctWarp::Create(const IctModel& model, std::span<const float> identity,
                                const IctWarpOptions& options) {
  ICEF_RETURN_IF_ERROR(options.Validate().WithContext("IctWarpOptions"));
  if (identity.size() > static_cast<size_t>(model.num_identities()))
    return Status::Error(std::to_string(identity.size()) + " identity coefficients for a model with " +
                         std::to_string(model.num_identities()));
  std::vector<bool> on_surface(model.part_names().size(), false);
  for (std::string_view part : kSurfaceParts) {
    const int index = model.PartIndex(part);
    if (index < 0)
      return Status::Error(model.path().string() + ": the face model has no part '" + std::string(part) +
                           "'");
    on_surface[index] = true;
  }
  IctWarp warp;
  warp.model_ = &model;
  warp.options_ = options;
  warp.neutral_ = model.Mesh(identity, {});
  const std::vector<uint8_t>& labels = model.part_labels();
  for (const auto& t : model.triangles())
    if (on_surface[labels[t[0]]] && on_surface[labels[t[1]]] && on_surface[labels[t[2]]])
      warp.triangles_.push_back(t);
  std::vector<bool> eyeball(model.part_names().size(), false);
  for (std::string_view part : kEyeballParts) eyeball[model.PartIndex(part)] = true;
  std::vector<std::array<uint32_t, 3>> skin;
  for (const auto& t : warp.triangles_)
    if (!eyeball[labels[t[0]]] && !eyeball[labels[t[1]]] && !eyeball[labels[t[2]]]) skin.push_back(t);
  for (int side = 0; side < 2; ++side) {
    warp.eyes_[side] = MeasureEye(warp.neutral_, labels, model.PartIndex(kScleras[side]), skin);
    warp.eyes_[side].blink = model.ExpressionIndex(kBlinks[side]);
  }
  return warp;
}

PosedIctWarp IctWarp::Pose(std::span<const float> expression) const {
  return PosedIctWarp(*this, expression);
}

std::vector<Vec3f> IctWarp::VertexNormals(const std::vector<Vec3f>& mesh) const {
  std::vector<Vec3f> normals(mesh.size(), Vec3f::Zero());
  for (const auto& t : triangles_) {
    const Vec3f n = (mesh[t[1]] - mesh[t[0]]).cross(mesh[t[2]] - mesh[t[0]]);
    for (uint32_t v : t) normals[v] += n;
  }
  for (Vec3f& n : normals)
    if (n.squaredNorm() > 0) n.normalize();
  return normals;
}

std::string IctWarp::ToString() const {
  std::ostringstream os;
  os << "IctWarp(triangles=" << triangles_.size() << " of " << model_->triangles().size() << ", "
     << options_.ToString() << ")";
  return os.str();
}

// ---------------------------------------------------------------------------------------------------------
// PosedIctWarp

// The KD-tree's points on the posed surface, and nanoflann's dataset interface to them. Heap-held:
// the index refers to it.
struct PosedIctWarp::Tree {
  using Index =
      nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<float, Tree>, Tree, 3, uint32_t>;
  struct Point {
    Vec3f position;     // head frame, cm
    uint32_t triangle;  // the surface triangle it lies on
    float cover;        // cm: its sub-triangle lies this close to it
  };
  std::vector<Point> points;  // in the index's leaf order once built (Build)
  std::unique_ptr<Index> index;

  size_t kdtree_get_point_count() const { return points.size(); }
  float kdtree_get_pt(uint32_t i, size_t dim) const {
    return points[i].position[static_cast<Eigen::Index>(dim)];
  }
  template <class Box>
  bool kdtree_get_bbox(Box&) const {
    return false;
  }

  // Builds the index, then stores the points in its leaf order (and makes its permutation the
  // identity): a leaf's points are then read from consecutive memory.
  void Build() {
    index = std::make_unique<Index>(3, *this, nanoflann::KDTreeSingleIndexAdaptorParams(10));
    std::vector<Point> ordered(points.size());
    for (size_t i = 0; i < points.size(); ++i) {
      ordered[i] = points[index->vAcc[i]];
      index->vAcc[i] = static_cast<uint32_t>(i);
    }
    points = std::move(ordered);
  }
};

namespace {

// A nanoflann result set that finds the closest triangle within outer_radius. Each KD-tree point
// found hands over its triangle unless |x - point| - cover rules it out; the triangle's exact
// distance is computed; the search radius shrinks to (best distance + largest cover), within which
// lies a point of every triangle closer than the best one.
class ClosestTriangleSearch {
 public:
  using DistanceType = float;
  using IndexType = uint32_t;

  ClosestTriangleSearch(const Vec3f& x, const std::vector<Vec3f>& mesh,
                        const std::vector<std::array<uint32_t, 3>>& triangles, const PosedIctWarp::Tree& tree,
                        float max_cover, float outer)
      : x_(x),
        mesh_(mesh),
        triangles_(triangles),
        tree_(tree),
        max_cover_(max_cover),
        limit_(outer),
        outer_(outer) {
    SetLimit(outer);
  }

  bool full() const { return true; }
  float worstDist() const { return radius_sq_; }
  bool addPoint(float distance_sq, uint32_t point) {
    const PosedIctWarp::Tree::Point& found = tree_.points[point];
    const uint32_t t = found.triangle;
    if (t == last_) return true;  // the points of a triangle come in runs
    if (std::sqrt(distance_sq) - found.cover > Margin(limit_)) return true;
    last_ = t;
    const Corners corners = TriangleCorners(mesh_, triangles_[t]);
    const Vec3f b = ClosestBarycentric(x_, corners);
    const float d_sq = (x_ - AtBarycentric(corners, b)).squaredNorm();
    if (d_sq < best_sq_ || (d_sq == best_sq_ && static_cast<int32_t>(t) < best_.triangle)) {
      best_sq_ = d_sq;
      best_.triangle = static_cast<int32_t>(t);
      best_.barycentric = b;
      SetLimit(std::sqrt(d_sq));
    }
    return true;
  }

  IctWarpClosest Result() const {
    if (best_.triangle < 0 || !(std::sqrt(best_sq_) < outer_)) return {};
    IctWarpClosest result = best_;
    result.distance = std::sqrt(best_sq_);
    return result;
  }

 private:
  // A relative and an absolute margin over float rounding: a triangle as close as the best one up to
  // rounding is still evaluated, so the smallest (distance, index) wins whatever the visiting order.
  static float Margin(float distance) { return distance * (1.f + 1e-5f) + 1e-5f; }
  void SetLimit(float distance) {
    limit_ = std::min(distance, outer_);
    const float radius = Margin(limit_ + max_cover_);
    radius_sq_ = radius * radius;
  }

  const Vec3f& x_;
  const std::vector<Vec3f>& mesh_;
  const std::vector<std::array<uint32_t, 3>>& triangles_;
  const PosedIctWarp::Tree& tree_;
  const float max_cover_;
  float limit_, radius_sq_ = 0;
  const float outer_;
  uint32_t last_ = UINT32_MAX;
  float best_sq_ = std::numeric_limits<float>::infinity();
  IctWarpClosest best_;
};

// Per vertex of the surface, the area-weighted sum of its triangles' rotations from `from` to `to`
// (quaternions, w >= 0; summed in triangle order), normalised; (0, 0, 0, 1) elsewhere.
std::vector<Vec4f> VertexRotations(const std::vector<Vec3f>& from, const std::vector<Vec3f>& to,
                                   const std::vector<std::array<uint32_t, 3>>& triangles) {
  std::vector<Vec4f> sums(from.size(), Vec4f::Zero());
  for (const auto& t : triangles) {
    const Corners c = TriangleCorners(from, t);
    const Vec4f q = TriangleRotation(c, TriangleCorners(to, t));
    const float area = 0.5f * (c[1] - c[0]).cross(c[2] - c[0]).norm();
    for (uint32_t v : t) sums[v] += area * q;
  }
  for (Vec4f& q : sums) {
    if (q.head<3>() == Vec3f::Zero())
      q = Vec4f(0, 0, 0, 1);  // all identities, or off the surface
    else
      q.normalize();
  }
  return sums;
}

}  // namespace

PosedIctWarp::PosedIctWarp(const IctWarp& warp, std::span<const float> expression)
    : warp_(&warp),
      expression_(expression.begin(), expression.end()),
      posed_(warp.neutral_),
      tree_(std::make_unique<Tree>()) {
  const IctModel& model = *warp.model_;
  ICEF_CHECK(expression.size() <= static_cast<size_t>(model.num_expressions()),
             std::to_string(expression.size()) + " expression weights for " +
                 std::to_string(model.num_expressions()) + " blendshapes");
  for (size_t e = 0; e < expression.size(); ++e) {
    ICEF_CHECK(std::isfinite(expression[e]), "expression weight " + std::to_string(e) + " is not finite");
    if (expression[e] == 0.f) continue;
    bool blink = false;  // the lid slide's, not the mesh's
    for (int side = 0; side < 2; ++side) {
      if (warp.eyes_[side].blink != static_cast<int>(e)) continue;
      blink_[side] = std::clamp(expression[e], 0.f, 1.f);
      blink = true;
    }
    if (blink) continue;
    const std::span<const Vec3f> delta = model.ExpressionDelta(static_cast<int>(e));
    for (size_t v = 0; v < posed_.size(); ++v) posed_[v] += expression[e] * delta[v];
  }
  vertex_rotations_ = VertexRotations(posed_, warp.neutral_, warp.triangles_);
  // KD-tree points: the centroids of an m x m subdivision of each triangle, in units of its edges
  // from corner 0: the upright sub-triangles (i, j), (i+1, j), (i, j+1) and the inverted ones
  // (i+1, j), (i, j+1), (i+1, j+1). A sub-triangle is the triangle scaled by 1/m (or its point
  // reflection), so it lies within CentroidRadius / m of its centroid.
  for (size_t t = 0; t < warp.triangles_.size(); ++t) {
    const Corners c = TriangleCorners(posed_, warp.triangles_[t]);
    const float radius = CentroidRadius(c);
    const int m = std::clamp(static_cast<int>(std::ceil(radius / warp.options_.tree_point_spacing)), 1,
                             kMaxSubdivisions);
    for (int i = 0; i < m; ++i) {
      for (int j = 0; i + j < m; ++j) {
        for (float shift : {1.f / 3.f, 2.f / 3.f}) {
          if (shift > 0.5f && i + j > m - 2) continue;
          const float u = (i + shift) / static_cast<float>(m), v = (j + shift) / static_cast<float>(m);
          const float cover = radius / static_cast<float>(m);
          tree_->points.push_back(
              {AtBarycentric(c, Vec3f(1.f - u - v, u, v)), static_cast<uint32_t>(t), cover});
          max_cover_ = std::max(max_cover_, cover);
        }
      }
    }
  }
  tree_->Build();
}

PosedIctWarp::PosedIctWarp(PosedIctWarp&&) noexcept = default;
PosedIctWarp& PosedIctWarp::operator=(PosedIctWarp&&) noexcept = default;
PosedIctWarp::~PosedIctWarp() = default;

IctWarpClosest PosedIctWarp::Closest(const Vec3f& x) const {
  ClosestTriangleSearch search(x, posed_, warp_->triangles_, *tree_, max_cover_,
                               warp_->options_.outer_radius);
  tree_->index->findNeighbors(search, x.data(), nanoflann::SearchParams());
  return search.Result();
}

Vec3f PosedIctWarp::LidSlide(const Vec3f& x) const {
  Vec3f y = x;
  for (int side = 0; side < 2; ++side) y = warp_->eyes_[side].Slide(y, blink_[side]);
  return y;
}

Vec3f PosedIctWarp::Offset(const Vec3f& x) const {
  const Vec3f y = LidSlide(x);
  return (y - x) + OffsetAt(y, Closest(y));
}

Vec3f PosedIctWarp::OffsetAt(const Vec3f& x, const IctWarpClosest& closest) const {
  if (closest.triangle < 0) return Vec3f::Zero();
  const IctWarpOptions& options = warp_->options_;
  const float weight = options.Weight(closest.distance);
  if (weight == 0.f) return Vec3f::Zero();
  const std::array<uint32_t, 3>& triangle = warp_->triangles_[closest.triangle];
  const Vec3f& b = closest.barycentric;
  const Vec3f p = AtBarycentric(TriangleCorners(posed_, triangle), b);
  const Vec3f p_canonical = AtBarycentric(TriangleCorners(warp_->neutral_, triangle), b);
  const Mat3f rotation =
      RotationOfSum(b[0] * vertex_rotations_[triangle[0]] + b[1] * vertex_rotations_[triangle[1]] +
                    b[2] * vertex_rotations_[triangle[2]]);
  const Vec3f along = x - p;
  // mapped - x = (p' - p) + (R - I)(x - p), summed in this order: exactly 0 where nothing moves.
  return weight * ((p_canonical - p) + (rotation * along - along));
}

void PosedIctWarp::Offsets(const Executor& executor, int64_t n, const float* positions,
                           float* offsets) const {
  ParallelForChunks(executor, n, BalancedChunk(n, 64, 4096), [&](int64_t begin, int64_t end) {
    for (int64_t i = begin; i < end; ++i) {
      const Vec3f offset = Offset(Eigen::Map<const Vec3f>(positions + 3 * i));
      Eigen::Map<Vec3f>(offsets + 3 * i) = offset;
    }
  });
}

std::string PosedIctWarp::ToString() const {
  std::ostringstream os;
  os << "PosedIctWarp(expression={";
  const std::vector<std::string>& names = warp_->model_->expression_names();
  bool first = true;
  for (size_t e = 0; e < expression_.size(); ++e) {
    if (expression_[e] == 0.f) continue;
    os << (first ? "" : ", ") << names[e] << "=" << expression_[e];
    first = false;
  }
  os << "}, tree_points=" << tree_->points.size() << ", max_cover=" << max_cover_ << " cm)";
  return os.str();
}

}  // namespace icef::face
