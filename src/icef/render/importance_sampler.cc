#include "icef/render/importance_sampler.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <vector>

#include "icef/core/rng.h"

namespace icef {

Status ImportanceOptions::Validate() const {
  if (num_samples < 0 || num_samples > 65536)
    return Status::Error("importance_samples must be in [0, 65536]");
  if (!(uniform >= 0.f && uniform <= 1.f)) return Status::Error("importance_uniform must be in [0, 1]");
  return Status::Ok();
}

std::string ImportanceOptions::ToString() const {
  std::ostringstream os;
  os << "ImportanceOptions(num_samples=" << num_samples << ", uniform=" << uniform << ")";
  return os.str();
}

namespace {

// The fine sample count of each coarse interval of one ray (counts[0..m)), summing to n.
void Allocate(const float* sigma, const float* dt, int64_t m, int n, float uniform, float jitter,
              int32_t* counts) {
  double transmittance = 1.0, weight_sum = 0.0, length = 0.0;
  // Two passes over the ray: the weights' sum first, then the cumulative allocation (the weights are
  // recomputed rather than stored).
  for (int64_t i = 0; i < m; ++i) {
    const double alpha = 1.0 - std::exp(-double(sigma[i]) * double(dt[i]));
    weight_sum += transmittance * alpha;
    transmittance *= 1.0 - alpha;
    length += dt[i];
  }
  const bool weighted = weight_sum > 1e-6;
  const double w_scale = weighted ? (1.0 - uniform) / weight_sum : 0.0;
  const double l_scale = length > 0 ? (weighted ? uniform : 1.0) / length : 0.0;
  transmittance = 1.0;
  double cumulative = 0.0;
  int64_t given = 0;
  for (int64_t i = 0; i < m; ++i) {
    const double alpha = 1.0 - std::exp(-double(sigma[i]) * double(dt[i]));
    const double w = transmittance * alpha;
    transmittance *= 1.0 - alpha;
    cumulative += n * (w * w_scale + dt[i] * l_scale);
    const int64_t upto = i + 1 == m ? n : std::min<int64_t>(n, int64_t(std::floor(cumulative + jitter)));
    counts[i] = int32_t(std::max<int64_t>(0, upto - given));
    given += counts[i];
  }
}

}  // namespace

void ResampleRays(std::span<const Ray> rays, const RaySamples& coarse, std::span<const float> sigma,
                  const ImportanceOptions& options, uint64_t seed, int64_t step, const Executor& executor,
                  RaySamples* out) {
  const Status status = options.Validate();
  ICEF_CHECK(status.ok(), "ResampleRays: " + status.ToString());
  ICEF_CHECK(options.enabled(), "ResampleRays: importance sampling is off (num_samples 0)");
  ICEF_CHECK(out != &coarse, "ResampleRays: out aliases coarse");
  ICEF_CHECK(int64_t(sigma.size()) == coarse.size(), "ResampleRays: one density per coarse sample");
  const int64_t num_rays = int64_t(rays.size());
  ICEF_CHECK(coarse.num_rays() == num_rays, "ResampleRays: coarse samples of other rays");
  const int n = options.num_samples;
  out->ray_offset.resize(num_rays);
  out->ray_count.resize(num_rays);
  int64_t total = 0;
  for (int64_t r = 0; r < num_rays; ++r) {
    out->ray_offset[r] = int32_t(total);
    out->ray_count[r] = coarse.ray_count[r] > 0 ? n : 0;
    total += out->ray_count[r];
  }
  ICEF_CHECK(total < (int64_t(1) << 31), "too many samples for int32 offsets");
  out->t.resize(total);
  out->dt.resize(total);
  out->positions.resize(3 * total);
  ParallelFor(executor, num_rays, [&](int64_t begin, int64_t end, int) {
    std::vector<int32_t> counts;
    for (int64_t r = begin; r < end; ++r) {
      const int64_t m = coarse.ray_count[r];
      if (m == 0) continue;
      const int64_t c0 = coarse.ray_offset[r];
      Rng rng(seed, StreamId("importance_jitter"), uint64_t(step), uint64_t(r));
      counts.resize(m);
      Allocate(sigma.data() + c0, coarse.dt.data() + c0, m, n, options.uniform, rng.Uniform(), counts.data());
      int64_t k = out->ray_offset[r];
      for (int64_t i = 0; i < m; ++i) {
        if (counts[i] == 0) continue;
        const float h = coarse.dt[c0 + i] / float(counts[i]);
        const float lo = coarse.t[c0 + i] - 0.5f * coarse.dt[c0 + i];
        for (int q = 0; q < counts[i]; ++q, ++k) {
          const float t = lo + (float(q) + 0.5f) * h;
          const Vec3f p = rays[r].At(t);
          out->t[k] = t;
          out->dt[k] = h;
          for (int a = 0; a < 3; ++a) out->positions[3 * k + a] = p[a];
        }
      }
    }
  });
}

}  // namespace icef
