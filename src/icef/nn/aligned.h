// 64-byte aligned float buffers for the parameter slab and kernel scratch, so AVX-512 loads of
// whole rows never split a cache line at the start of a buffer.
#pragma once

#include <cstddef>
#include <new>
#include <vector>

namespace icef::nn {

inline constexpr std::size_t kAlignment = 64;

template <typename T>
struct AlignedAllocator {
  using value_type = T;
  AlignedAllocator() = default;
  template <typename U>
  AlignedAllocator(const AlignedAllocator<U>&) {}  // NOLINT: rebind
  T* allocate(std::size_t n) {
    return static_cast<T*>(::operator new(n * sizeof(T), std::align_val_t(kAlignment)));
  }
  void deallocate(T* p, std::size_t) { ::operator delete(p, std::align_val_t(kAlignment)); }
  template <typename U>
  bool operator==(const AlignedAllocator<U>&) const {
    return true;
  }
};

template <typename T>
using AlignedVector = std::vector<T, AlignedAllocator<T>>;

// Grows a buffer to at least `size` elements, never shrinking it (per-batch workspaces).
template <typename V>
void GrowTo(V& v, long long size) {
  if (static_cast<long long>(v.size()) < size) v.resize(size);
}

// Rounds n up to a multiple of 16 floats (one cache line), the granularity of slab blocks.
constexpr long long RoundUpToLine(long long n) { return (n + 15) / 16 * 16; }

}  // namespace icef::nn
