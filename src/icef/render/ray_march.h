// Front-to-back compositing in rounds, with early ray termination for inference (docs/design.md §3).
// CompositeForward needs every sample's density and colour before it composites; a renderer that
// evaluates the fields only where they can still change a pixel marches instead:
//
//   RayMarch march;
//   march.Start(samples, num_extras);
//   while (march.NextRound(samples)) {
//     // evaluate the fields at the round's rows: row i of active ray k (round_begin(k) <= i <
//     // round_end(k)) is sample march.Sample(k, i) of `samples`
//     march.Composite(samples, sigma, rgb, extras, eps, executor);
//   }
//   ... march.color(r), opacity(r), depth(r), extra(r, e)
//
// Each round takes the next few samples of every ray still marching (more per ray as fewer rays
// remain); a ray stops after the first sample that leaves its transmittance below
// transmittance_eps, exactly where CompositeRayForward stops, with the same float operations in
// the same order: the results equal CompositeForward's over all samples (to the last bit, up to
// how the compiler fuses multiply-adds), while the samples behind an opaque surface are never
// evaluated. `extras` are per-sample scalars
// accumulated as sum_i w_i v_i (e.g. the expected region mask).
#pragma once

#include <cstdint>
#include <vector>

#include "icef/core/parallel.h"
#include "icef/render/ray_sampler.h"

namespace icef {

class RayMarch {
 public:
  // Every ray of `samples` with at least one sample starts marching at transmittance 1.
  void Start(const RaySamples& samples, int num_extras);

  // Chooses the next round's rows; false when no ray is left. Each active ray gets up to
  // clamp(target_rows / active rays, min_per_ray, max_per_ray) of its next samples.
  bool NextRound(const RaySamples& samples, int64_t target_rows = 1 << 16, int min_per_ray = 4,
                 int max_per_ray = 8);

  int64_t round_size() const { return round_rows_; }
  int64_t active() const { return int64_t(active_.size()); }
  // Ray (index into samples' rays) of active ray k, its rows [round_begin, round_end) in this round.
  int32_t ray(int64_t k) const { return active_[k]; }
  int64_t round_begin(int64_t k) const { return row_begin_[k]; }
  int64_t round_end(int64_t k) const { return row_begin_[k + 1]; }
  // The sample of `samples` that row i (of active ray k) holds.
  int64_t Sample(int64_t k, int64_t i) const { return next_[active_[k]] + (i - row_begin_[k]); }

  // Composites this round's rows: sigma [rows], rgb [rows, 3], extras [rows, num_extras] (may be
  // null when num_extras = 0). Rays that terminate or run out of samples stop marching.
  void Composite(const RaySamples& samples, const float* sigma, const float* rgb, const float* extras,
                 float transmittance_eps, const Executor& executor);

  // Results per ray of `samples` (rays that never marched: colour = background, opacity 0).
  void Color(int64_t r, const float background[3], float color[3]) const {
    for (int k = 0; k < 3; ++k) color[k] = acc_[stride_ * r + k] + trans_[r] * background[k];
  }
  float opacity(int64_t r) const { return 1.f - trans_[r]; }
  float depth(int64_t r) const { return acc_[stride_ * r + 3]; }
  float extra(int64_t r, int e) const { return acc_[stride_ * r + 4 + e]; }

 private:
  int num_extras_ = 0;
  int stride_ = 4;
  std::vector<int32_t> active_;     // rays still marching
  std::vector<int32_t> next_;       // [rays] first sample not yet composited
  std::vector<int64_t> row_begin_;  // [active + 1] this round's rows per active ray
  int64_t round_rows_ = 0;
  std::vector<float> trans_;   // [rays] transmittance so far
  std::vector<uint8_t> done_;  // [rays] terminated
  std::vector<float> acc_;     // [rays, 4 + num_extras] colour, depth, extras
};

}  // namespace icef
