#include "icef/field/prior_shading.h"

namespace icef {

void ApplyPriorShading(const Executor& executor, int64_t n, const float* n_obs, const float* n_can,
                       const Vec3f& light, float* rgb, float* shade) {
  ParallelFor(executor, n, [&](int64_t i0, int64_t i1, int) {
    for (int64_t i = i0; i < i1; ++i) {
      const float s = PriorShadeRatio(n_obs + 3 * i, n_can + 3 * i, light);
      shade[i] = s;
      for (int a = 0; a < 3; ++a) rgb[3 * i + a] *= s;
    }
  });
}

}  // namespace icef
