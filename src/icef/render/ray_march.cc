#include "icef/render/ray_march.h"

#include <algorithm>
#include <cmath>

namespace icef {

void RayMarch::Start(const RaySamples& samples, int num_extras) {
  const int64_t rays = samples.num_rays();
  num_extras_ = num_extras;
  stride_ = 4 + num_extras;
  next_.assign(samples.ray_offset.begin(), samples.ray_offset.end());
  trans_.assign(rays, 1.f);
  done_.assign(rays, 0);
  acc_.assign(size_t(stride_) * rays, 0.f);
  active_.clear();
  for (int64_t r = 0; r < rays; ++r)
    if (samples.ray_count[r] > 0) active_.push_back(static_cast<int32_t>(r));
  row_begin_.assign(1, 0);
  round_rows_ = 0;
}

bool RayMarch::NextRound(const RaySamples& samples, int64_t target_rows, int min_per_ray, int max_per_ray) {
  // Drop the rays the last round finished.
  std::erase_if(active_, [&](int32_t r) {
    return done_[r] || next_[r] >= samples.ray_offset[r] + samples.ray_count[r];
  });
  if (active_.empty()) return false;
  const int64_t per_ray = std::clamp<int64_t>(target_rows / int64_t(active_.size()), min_per_ray,
                                              std::max(min_per_ray, max_per_ray));
  row_begin_.resize(active_.size() + 1);
  row_begin_[0] = 0;
  for (size_t k = 0; k < active_.size(); ++k) {
    const int32_t r = active_[k];
    const int64_t left = samples.ray_offset[r] + samples.ray_count[r] - next_[r];
    row_begin_[k + 1] = row_begin_[k] + std::min(per_ray, left);
  }
  round_rows_ = row_begin_.back();
  return true;
}

void RayMarch::Composite(const RaySamples& samples, const float* sigma, const float* rgb, const float* extras,
                         float transmittance_eps, const Executor& executor) {
  ParallelFor(executor, active(), [&](int64_t begin, int64_t end, int) {
    for (int64_t k = begin; k < end; ++k) {
      const int32_t r = active_[k];
      float* acc = acc_.data() + size_t(stride_) * r;
      float trans = trans_[r];
      int64_t s = next_[r];
      // The arithmetic of CompositeRayForward, sample by sample.
      for (int64_t i = row_begin_[k]; i < row_begin_[k + 1]; ++i, ++s) {
        const float alpha = 1.f - std::exp(-sigma[i] * samples.dt[s]);
        const float w = trans * alpha;
        for (int c = 0; c < 3; ++c) acc[c] += w * rgb[3 * i + c];
        acc[3] += w * samples.t[s];
        for (int e = 0; e < num_extras_; ++e) acc[4 + e] += w * extras[size_t(num_extras_) * i + e];
        trans *= 1.f - alpha;
        if (trans < transmittance_eps) {
          done_[r] = 1;
          ++s;
          break;
        }
      }
      trans_[r] = trans;
      next_[r] = static_cast<int32_t>(s);
    }
  });
}

}  // namespace icef
