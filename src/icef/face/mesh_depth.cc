#include "icef/face/mesh_depth.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

namespace icef::face {

namespace {

// Möller-Trumbore: t of the ray (origin, unit direction) through triangle (a, b, c), or nullopt.
std::optional<double> Intersect(const Vec3d& origin, const Vec3d& direction, const Vec3d& a, const Vec3d& b,
                                const Vec3d& c) {
  const Vec3d e1 = b - a, e2 = c - a;
  const Vec3d p = direction.cross(e2);
  const double det = e1.dot(p);
  if (std::abs(det) < 1e-18) return std::nullopt;
  const double inv = 1.0 / det;
  const Vec3d s = origin - a;
  const double u = s.dot(p) * inv;
  if (u < 0 || u > 1) return std::nullopt;
  const Vec3d q = s.cross(e1);
  const double v = direction.dot(q) * inv;
  if (v < 0 || u + v > 1) return std::nullopt;
  const double t = e2.dot(q) * inv;
  if (t <= 0) return std::nullopt;
  return t;
}

}  // namespace

std::vector<float> MeshDepthImage(std::span<const Vec3f> vertices,
                                  std::span<const std::array<uint32_t, 3>> triangles, const Camera& camera,
                                  std::vector<int32_t>* hit_triangle) {
  const int width = camera.width(), height = camera.height();
  std::vector<float> depth(size_t(width) * height, std::numeric_limits<float>::infinity());
  if (hit_triangle) hit_triangle->assign(depth.size(), -1);
  std::vector<std::optional<Vec2d>> uv(vertices.size());
  for (size_t v = 0; v < vertices.size(); ++v)
    if (const auto p = camera.Project(vertices[v].cast<double>())) uv[v] = p->uv;
  const Vec3d origin = camera.Center();
  for (size_t index = 0; index < triangles.size(); ++index) {
    const auto& t = triangles[index];
    if (!uv[t[0]] || !uv[t[1]] || !uv[t[2]]) continue;
    const Vec2d lo = uv[t[0]]->cwiseMin(*uv[t[1]]).cwiseMin(*uv[t[2]]);
    const Vec2d hi = uv[t[0]]->cwiseMax(*uv[t[1]]).cwiseMax(*uv[t[2]]);
    // Pixel centres (i + 0.5) within [lo, hi], one pixel of slack for the rounding of the projection.
    const int x0 = std::max(0, static_cast<int>(std::floor(lo.x() - 0.5)) - 1);
    const int y0 = std::max(0, static_cast<int>(std::floor(lo.y() - 0.5)) - 1);
    const int x1 = std::min(width - 1, static_cast<int>(std::ceil(hi.x() - 0.5)) + 1);
    const int y1 = std::min(height - 1, static_cast<int>(std::ceil(hi.y() - 0.5)) + 1);
    if (x0 > x1 || y0 > y1) continue;
    const Vec3d a = vertices[t[0]].cast<double>(), b = vertices[t[1]].cast<double>(),
                c = vertices[t[2]].cast<double>();
    for (int y = y0; y <= y1; ++y)
      for (int x = x0; x <= x1; ++x) {
        const Ray ray = camera.PixelRay(x, y);
        const auto hit = Intersect(origin, ray.direction.cast<double>(), a, b, c);
        float& d = depth[size_t(y) * width + x];
        if (!hit || !(*hit < d)) continue;
        d = static_cast<float>(*hit);
        if (hit_triangle) (*hit_triangle)[size_t(y) * width + x] = static_cast<int32_t>(index);
      }
  }
  return depth;
}

}  // namespace icef::face
