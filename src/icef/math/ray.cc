#include "icef/math/ray.h"

#include <algorithm>
#include <limits>

namespace icef {

std::optional<Interval> Aabb::Intersect(const Ray& ray) const {
  float t0 = 0.f;
  float t1 = std::numeric_limits<float>::infinity();
  for (int a = 0; a < 3; ++a) {
    const float d = ray.direction[a];
    const float o = ray.origin[a];
    if (d == 0.f) {
      if (o < min[a] || o > max[a]) return std::nullopt;
      continue;
    }
    const float inv = 1.f / d;
    float ta = (min[a] - o) * inv;
    float tb = (max[a] - o) * inv;
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
    if (t0 > t1) return std::nullopt;
  }
  return Interval{t0, t1};
}

std::string Ray::ToString() const {
  return "Ray(origin=" + icef::ToString(origin.cast<double>()) +
         ", direction=" + icef::ToString(direction.cast<double>()) + ")";
}

std::string Aabb::ToString() const {
  return "Aabb(min=" + icef::ToString(min.cast<double>()) + ", max=" + icef::ToString(max.cast<double>()) +
         ")";
}

}  // namespace icef
