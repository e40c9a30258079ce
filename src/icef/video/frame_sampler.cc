#include "icef/video/frame_sampler.h"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <utility>

namespace icef {

std::vector<int64_t> EvenlySpreadIndices(int count, int64_t total) {
  std::vector<int64_t> indices;
  if (count <= 0 || total <= 0) return indices;
  if (total <= count) {
    for (int64_t i = 0; i < total; ++i) indices.push_back(i);
    return indices;
  }
  if (count == 1) return {(total - 1) / 2};
  const double step = double(total - 1) / (count - 1);  // >= 1, so the rounded positions are distinct
  for (int k = 0; k < count; ++k) indices.push_back(std::llround(k * step));
  return indices;
}

EvenFrameSampler::EvenFrameSampler(int count, int64_t total_estimate)
    : count_(std::max(count, 1)), targets_(EvenlySpreadIndices(count_, total_estimate)) {}

bool EvenFrameSampler::Offer(int64_t index) {
  bool hold = false;
  if (next_target_ < targets_.size() && targets_[next_target_] == index) {
    ++next_target_;
    hold = true;
  }
  if (index % stride_ != 0) return hold;
  reserve_.push_back(index);
  if (reserve_.size() <= size_t(2) * count_) return true;
  stride_ *= 2;
  std::vector<int64_t> kept;
  for (int64_t i : reserve_) {
    if (i % stride_ == 0) {
      kept.push_back(i);
    } else if (!std::binary_search(targets_.begin(), targets_.end(), i)) {
      if (i == index) continue;  // never handed out: not held at all
      released_.push_back(i);
    }
  }
  reserve_ = std::move(kept);
  return hold || index % stride_ == 0;
}

std::vector<int64_t> EvenFrameSampler::TakeReleased() { return std::exchange(released_, {}); }

std::vector<int64_t> EvenFrameSampler::Choose(int64_t decoded) const {
  std::vector<int64_t> held;
  std::set_union(targets_.begin(), targets_.begin() + next_target_, reserve_.begin(), reserve_.end(),
                 std::back_inserter(held));
  const std::vector<int64_t> ideal = EvenlySpreadIndices(count_, decoded);
  if (held.size() <= ideal.size()) return held;
  // Greedy in order: each ideal position takes the nearest held frame after the previous choice,
  // leaving enough frames for the positions still to come.
  std::vector<int64_t> chosen;
  size_t lo = 0;
  for (size_t k = 0; k < ideal.size(); ++k) {
    const size_t hi = held.size() - (ideal.size() - k);  // the last position this one may take
    size_t j = std::lower_bound(held.begin() + lo, held.begin() + hi + 1, ideal[k]) - held.begin();
    if (j > hi) {
      j = hi;
    } else if (j > lo && ideal[k] - held[j - 1] <= held[j] - ideal[k]) {
      --j;
    }
    chosen.push_back(held[j]);
    lo = j + 1;
  }
  return chosen;
}

}  // namespace icef
