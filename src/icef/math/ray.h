// Rays and axis-aligned boxes. Frames: both in the world (head) frame unless stated.
#pragma once

#include <optional>
#include <string>

#include "icef/math/types.h"

namespace icef {

struct Ray {
  Vec3f origin;     // world frame
  Vec3f direction;  // world frame, unit length
  Vec3f At(float t) const { return origin + t * direction; }
  std::string ToString() const;
};

struct Interval {
  float t_near;
  float t_far;
};

struct Aabb {
  Vec3f min = Vec3f::Constant(-1.f);
  Vec3f max = Vec3f::Constant(1.f);

  Vec3f Extent() const { return max - min; }
  Vec3f Center() const { return 0.5f * (min + max); }
  bool Contains(const Vec3f& p) const {
    return (p.array() >= min.array()).all() && (p.array() <= max.array()).all();
  }
  bool IsValid() const { return (max.array() > min.array()).all() && min.allFinite() && max.allFinite(); }
  // Maps p to [0,1]^3 box coordinates.
  Vec3f Normalize(const Vec3f& p) const { return (p - min).cwiseQuotient(Extent()); }
  // The parameter interval where the ray is inside the box, clipped to t >= 0; nullopt if it
  // misses (slab method; handles axis-parallel rays).
  std::optional<Interval> Intersect(const Ray& ray) const;
  std::string ToString() const;
};

}  // namespace icef
