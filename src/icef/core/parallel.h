// Explicit thread pool handle (no global state, STYLE.md habit 3) and deterministic parallel loops
// built on OpenMP. ParallelFor splits [0, n) into num_threads contiguous ranges: range t always
// goes to thread index t, so per-thread accumulators reduced in thread order give results that do
// not depend on scheduling.
#pragma once

#include <cstdint>
#include <functional>
#include <string>

namespace icef {

class Executor {
 public:
  // num_threads <= 0 picks the hardware concurrency.
  explicit Executor(int num_threads = 0);
  int num_threads() const { return num_threads_; }
  std::string ToString() const { return "Executor(threads=" + std::to_string(num_threads_) + ")"; }

 private:
  int num_threads_;
};

// fn(begin, end, thread_index) for the contiguous range of thread_index; ranges are fixed by
// (n, num_threads). Exceptions thrown inside fn are rethrown on the calling thread.
void ParallelFor(const Executor& executor, int64_t n,
                 const std::function<void(int64_t begin, int64_t end, int thread)>& fn);

// fn(begin, end) over chunks of `chunk` items handed out dynamically (load-balanced). Use only
// when each chunk writes its own outputs: which thread runs a chunk is not deterministic.
void ParallelForChunks(const Executor& executor, int64_t n, int64_t chunk,
                       const std::function<void(int64_t begin, int64_t end)>& fn);

// Chunks ParallelForChunks should cut a batch into so that the threads finish together: with
// whole-batch chunks of a fixed size, a batch of one chunk ran on one thread, and one of 7.5
// chunks left a thread idle for half a chunk.
inline constexpr int64_t kBalancedChunks = 16;

// Items per chunk for a batch of n: n / kBalancedChunks rounded up to whole granules, within
// [granule, max_chunk] (max_chunk a multiple of granule). A function of its arguments alone, never
// of the thread count, so chunk-ordered reductions stay bit-identical for any thread count.
constexpr int64_t BalancedChunk(int64_t n, int64_t granule, int64_t max_chunk) {
  const int64_t granules = (n + kBalancedChunks * granule - 1) / (kBalancedChunks * granule);
  const int64_t chunk = (granules < 1 ? 1 : granules) * granule;
  return chunk < max_chunk ? chunk : max_chunk;
}

}  // namespace icef
