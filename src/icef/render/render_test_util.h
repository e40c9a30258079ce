// Test-only helpers of render/'s tests.
#pragma once

#include <cstdint>
#include <vector>

#include "icef/core/rng.h"
#include "icef/math/ray.h"

namespace icef::testing_render {

// n rays from z = 3 (x, y in [-3, 3]) through random points of [-0.8, 0.8]^3, unit directions.
inline std::vector<Ray> RandomRays(int n, uint64_t seed) {
  Rng rng(seed, StreamId("test_rays"));
  std::vector<Ray> rays;
  for (int i = 0; i < n; ++i) {
    Vec3f target(rng.Uniform(-0.8, 0.8), rng.Uniform(-0.8, 0.8), rng.Uniform(-0.8, 0.8));
    Vec3f origin(rng.Uniform(-3, 3), rng.Uniform(-3, 3), 3.f);
    rays.push_back(Ray{origin, (target - origin).normalized()});
  }
  return rays;
}

}  // namespace icef::testing_render
