#include "icef/render/distortion_loss.h"

#include "icef/core/status.h"

namespace icef {

template <typename T>
T DistortionLoss(std::span<const T> weights, std::span<const T> t, std::span<const T> dt,
                 std::span<const int32_t> ray_offset, std::span<const int32_t> ray_count, T scale,
                 const Executor& executor, std::vector<T>* d_weights) {
  ICEF_CHECK(weights.size() == t.size() && t.size() == dt.size(), "distortion loss: sample array sizes");
  ICEF_CHECK(ray_offset.size() == ray_count.size(), "distortion loss: ray array sizes");
  const int64_t rays = int64_t(ray_offset.size());
  if (rays == 0) return T(0);
  if (d_weights) d_weights->assign(weights.size(), T(0));
  std::vector<T> per_thread(executor.num_threads(), T(0));
  const T inv_rays = T(1) / T(rays);
  ParallelFor(executor, rays, [&](int64_t begin, int64_t end, int thread) {
    T sum = T(0);
    for (int64_t r = begin; r < end; ++r) {
      const int64_t o = ray_offset[r];
      const int n = ray_count[r];
      sum += DistortionLossRay<T>(n, weights.data() + o, t.data() + o, dt.data() + o);
      if (d_weights)
        DistortionLossRayBackward<T>(n, weights.data() + o, t.data() + o, dt.data() + o, scale * inv_rays,
                                     d_weights->data() + o);
    }
    per_thread[thread] = sum;
  });
  T total = T(0);
  for (T s : per_thread) total += s;  // fixed thread order: deterministic
  return total * inv_rays;
}

template float DistortionLoss<float>(std::span<const float>, std::span<const float>, std::span<const float>,
                                     std::span<const int32_t>, std::span<const int32_t>, float,
                                     const Executor&, std::vector<float>*);
template double DistortionLoss<double>(std::span<const double>, std::span<const double>,
                                       std::span<const double>, std::span<const int32_t>,
                                       std::span<const int32_t>, double, const Executor&,
                                       std::vector<double>*);

}  // namespace icef
