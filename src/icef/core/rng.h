// Counter-based random numbers (STYLE.md habit 4): every draw is a pure function of
// (seed, purpose, step, item, index), so no thread shares RNG state and results do not depend on
// scheduling. Rng is a cheap value type: construct one per (purpose, step, item) where needed.
#pragma once

#include <cstdint>
#include <string>

namespace icef {

// SplitMix64 finaliser: a strong 64-bit mixing function.
constexpr uint64_t Mix64(uint64_t x) {
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

// Hashes a purpose name to a stream id at compile time (FNV-1a).
constexpr uint64_t StreamId(const char* purpose) {
  uint64_t h = 0xcbf29ce484222325ULL;
  for (const char* p = purpose; *p; ++p) h = (h ^ static_cast<uint8_t>(*p)) * 0x100000001b3ULL;
  return h;
}

class Rng {
 public:
  // A stream identified by (seed, purpose, step, item); draws advance a counter within it.
  Rng(uint64_t seed, uint64_t purpose, uint64_t step = 0, uint64_t item = 0)
      : key_(Mix64(Mix64(Mix64(seed ^ Mix64(purpose)) ^ step) ^ item)) {}

  uint64_t NextU64() { return Mix64(key_ + 0x632be59bd9b4e019ULL * (++counter_)); }
  uint32_t NextU32() { return static_cast<uint32_t>(NextU64() >> 32); }
  // Uniform in [0, 1).
  float Uniform() { return static_cast<float>(NextU64() >> 40) * (1.0f / 16777216.0f); }
  double UniformDouble() { return static_cast<double>(NextU64() >> 11) * (1.0 / 9007199254740992.0); }
  // Uniform in [lo, hi).
  double Uniform(double lo, double hi) { return lo + (hi - lo) * UniformDouble(); }
  // Uniform integer in [0, n).
  uint64_t Below(uint64_t n) { return n == 0 ? 0 : NextU64() % n; }
  // Standard normal (Box-Muller).
  double Normal();
  // Jumps to draw index `index` of this stream (pbrt's Advance), so item i's k-th draw is fixed.
  void Advance(uint64_t index) { counter_ = index; }

  std::string ToString() const;

 private:
  uint64_t key_;
  uint64_t counter_ = 0;
};

}  // namespace icef
