#include "icef/core/parallel.h"

#include <omp.h>

#include <algorithm>
#include <exception>
#include <mutex>
#include <thread>

namespace icef {

Executor::Executor(int num_threads) {
  if (num_threads <= 0) num_threads = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  num_threads_ = num_threads;
}

namespace {
// Captures the first exception thrown by any worker so it can be rethrown on the caller.
class ExceptionSlot {
 public:
  void Capture() {
    std::lock_guard<std::mutex> lock(mu_);
    if (!error_) error_ = std::current_exception();
  }
  void Rethrow() {
    if (error_) std::rethrow_exception(error_);
  }

 private:
  std::mutex mu_;
  std::exception_ptr error_;
};
}  // namespace

void ParallelFor(const Executor& executor, int64_t n, const std::function<void(int64_t, int64_t, int)>& fn) {
  if (n <= 0) return;
  const int threads = static_cast<int>(std::min<int64_t>(executor.num_threads(), n));
  if (threads == 1) {
    fn(0, n, 0);
    return;
  }
  ExceptionSlot slot;
#pragma omp parallel num_threads(threads)
  {
    const int t = omp_get_thread_num();
    const int64_t begin = n * t / threads;
    const int64_t end = n * (t + 1) / threads;
    try {
      if (begin < end) fn(begin, end, t);
    } catch (...) {
      slot.Capture();
    }
  }
  slot.Rethrow();
}

void ParallelForChunks(const Executor& executor, int64_t n, int64_t chunk,
                       const std::function<void(int64_t, int64_t)>& fn) {
  if (n <= 0) return;
  chunk = std::max<int64_t>(1, chunk);
  const int64_t num_chunks = (n + chunk - 1) / chunk;
  const int threads = static_cast<int>(std::min<int64_t>(executor.num_threads(), num_chunks));
  if (threads == 1) {
    fn(0, n);
    return;
  }
  ExceptionSlot slot;
#pragma omp parallel for num_threads(threads) schedule(dynamic, 1)
  for (int64_t c = 0; c < num_chunks; ++c) {
    try {
      fn(c * chunk, std::min(n, (c + 1) * chunk));
    } catch (...) {
      slot.Capture();
    }
  }
  slot.Rethrow();
}

}  // namespace icef
