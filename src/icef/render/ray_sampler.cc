#include "icef/render/ray_sampler.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "icef/core/rng.h"

namespace icef {

Status RaySamplerOptions::Validate() const {
  if (num_samples < 1 || num_samples > 65536)
    return Status::Error("sampler.num_samples must be in [1, 65536]");
  if (!(step_size >= 0.f) || !std::isfinite(step_size))
    return Status::Error("sampler.step_size must be >= 0");
  if (!(cone_angle >= 0.f) || !std::isfinite(cone_angle))
    return Status::Error("sampler.cone_angle must be >= 0");
  if (max_samples < 1 || max_samples > 65536)
    return Status::Error("sampler.max_samples must be in [1, 65536]");
  return Status::Ok();
}

std::string RaySamplerOptions::ToString() const {
  std::ostringstream os;
  os << "RaySamplerOptions(num_samples=" << num_samples << ", step_size=" << step_size
     << ", cone_angle=" << cone_angle << ", max_samples=" << max_samples
     << ", stratified=" << (stratified ? "true" : "false") << ")";
  return os.str();
}

std::string RaySamples::ToString() const {
  std::ostringstream os;
  os << "RaySamples(rays=" << num_rays() << ", samples=" << size() << ")";
  return os.str();
}

namespace {

// Visits the candidate samples of one ray in order: fn(t, dt) for each; returns nothing.
template <typename Fn>
void ForEachCandidate(const Ray& ray, const Interval& iv, const RaySamplerOptions& o, float jitter, Fn&& fn) {
  if (!o.Marching()) {
    const float dt = (iv.t_far - iv.t_near) / float(o.num_samples);
    if (!(dt > 0.f)) return;
    for (int i = 0; i < o.num_samples; ++i) fn(iv.t_near + (float(i) + jitter) * dt, dt);
    return;
  }
  auto step_at = [&](float t) { return std::max(o.step_size, o.cone_angle * t); };
  float dt = step_at(iv.t_near);
  if (!(dt > 0.f)) dt = 1e-6f;  // cone mode with t_near = 0 and no minimum step
  float t = iv.t_near + jitter * dt;
  for (int i = 0; i < o.max_samples && t < iv.t_far; ++i) {
    fn(t, dt);
    const float next_dt = std::max(step_at(t + dt), 1e-6f);
    t += 0.5f * (dt + next_dt);  // keeps the intervals [t - dt/2, t + dt/2] contiguous
    dt = next_dt;
  }
  (void)ray;
}

}  // namespace

void SampleRays(std::span<const Ray> rays, const Aabb& aabb, const RaySamplerOptions& options,
                const OccupancyGrid* grid, uint64_t seed, int64_t step, const Executor& executor,
                RaySamples* out) {
  const Status status = options.Validate();
  ICEF_CHECK(status.ok(), status.ToString());
  const int64_t num_rays = int64_t(rays.size());
  out->ray_offset.resize(num_rays);
  out->ray_count.resize(num_rays);
  auto jitter_of = [&](int64_t r) {
    if (!options.stratified) return 0.5f;
    Rng rng(seed, StreamId("ray_jitter"), uint64_t(step), uint64_t(r));
    return rng.Uniform();
  };
  // Pass 1: count the kept samples of every ray.
  ParallelFor(executor, num_rays, [&](int64_t begin, int64_t end, int) {
    for (int64_t r = begin; r < end; ++r) {
      const std::optional<Interval> iv = aabb.Intersect(rays[r]);
      int32_t count = 0;
      if (iv) {
        ForEachCandidate(rays[r], *iv, options, jitter_of(r), [&](float t, float) {
          if (!grid || grid->IsOccupied(rays[r].At(t))) ++count;
        });
      }
      out->ray_count[r] = count;
    }
  });
  int64_t total = 0;
  for (int64_t r = 0; r < num_rays; ++r) {
    out->ray_offset[r] = int32_t(total);
    total += out->ray_count[r];
  }
  ICEF_CHECK(total < (int64_t(1) << 31), "too many samples for int32 offsets");
  out->t.resize(total);
  out->dt.resize(total);
  out->positions.resize(3 * total);
  // Pass 2: write them.
  ParallelFor(executor, num_rays, [&](int64_t begin, int64_t end, int) {
    for (int64_t r = begin; r < end; ++r) {
      if (out->ray_count[r] == 0) continue;
      const Interval iv = *aabb.Intersect(rays[r]);
      int64_t k = out->ray_offset[r];
      ForEachCandidate(rays[r], iv, options, jitter_of(r), [&](float t, float dt) {
        const Vec3f p = rays[r].At(t);
        if (grid && !grid->IsOccupied(p)) return;
        out->t[k] = t;
        out->dt[k] = dt;
        out->positions[3 * k + 0] = p.x();
        out->positions[3 * k + 1] = p.y();
        out->positions[3 * k + 2] = p.z();
        ++k;
      });
    }
  });
}

}  // namespace icef
