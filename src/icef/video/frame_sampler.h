// Internal to the video module: which decoded frames to hold so that `count` frames end up spread
// evenly over a video whose frame count is only estimated until decoding ends, without holding
// every frame. Two sets are held: the frames at the estimate's even positions, and a reserve thinned
// by halving (every s-th frame, s doubling whenever more than 2 * count are held), which covers the
// whole video at a spacing of at most decoded / count when the estimate proves wrong.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace icef {

// `count` indices spread evenly over [0, total): the first and the last included (one: the
// middle); all of them when total <= count; none when total <= 0.
std::vector<int64_t> EvenlySpreadIndices(int count, int64_t total);

class EvenFrameSampler {
 public:
  // count >= 1; total_estimate <= 0 when unknown.
  EvenFrameSampler(int count, int64_t total_estimate);

  // Called for each decoded frame in order 0, 1, 2, ...: whether to hold it.
  bool Offer(int64_t index);
  // Frames held earlier that are no longer needed (the list is cleared); call after each Offer.
  std::vector<int64_t> TakeReleased();
  // Once `decoded` frames were offered: min(count, held) held frames closest to the even spread
  // over [0, decoded), in order.
  std::vector<int64_t> Choose(int64_t decoded) const;

 private:
  int count_;
  std::vector<int64_t> targets_;  // even positions by the estimate, ascending
  size_t next_target_ = 0;        // the first target not yet offered
  std::vector<int64_t> reserve_;  // held multiples of stride_, ascending
  int64_t stride_ = 1;
  std::vector<int64_t> released_;
};

}  // namespace icef
