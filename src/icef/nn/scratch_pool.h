// Per-worker scratch for dynamically scheduled loops (icef::ParallelForChunks, which does not
// say which thread runs a chunk): a chunk borrows one object for its duration, so at most as
// many objects exist as chunks run at once. Objects are kept for reuse: no allocation once warm.
// Determinism comes from what the chunk writes (its own outputs, per-chunk accumulators reduced
// in chunk order), never from which scratch object it borrowed.
#pragma once

#include <memory>
#include <mutex>
#include <vector>

namespace icef::nn {

template <typename T>
class ScratchPool {
 public:
  // Returns a free object, creating one with make() (returning std::unique_ptr<T>) if none is free.
  template <typename Factory>
  T* Acquire(const Factory& make) {
    std::lock_guard<std::mutex> lock(mu_);
    if (free_.empty()) {
      all_.push_back(make());
      return all_.back().get();
    }
    T* t = free_.back();
    free_.pop_back();
    return t;
  }
  void Release(T* t) {
    std::lock_guard<std::mutex> lock(mu_);
    free_.push_back(t);
  }
  // RAII borrow.
  class Lease {
   public:
    Lease(ScratchPool* pool, T* t) : pool_(pool), t_(t) {}
    ~Lease() { pool_->Release(t_); }
    Lease(const Lease&) = delete;
    Lease& operator=(const Lease&) = delete;
    T& operator*() const { return *t_; }
    T* operator->() const { return t_; }

   private:
    ScratchPool* pool_;
    T* t_;
  };
  template <typename Factory>
  Lease Borrow(const Factory& make) {
    return Lease(this, Acquire(make));
  }

 private:
  std::mutex mu_;
  std::vector<std::unique_ptr<T>> all_;
  std::vector<T*> free_;
};

}  // namespace icef::nn

#include <atomic>
#include <cstdint>

#include "icef/core/status.h"

namespace icef::nn {

// Hands out slot indices 0..num_slots-1 (num_slots <= 64) to concurrently running chunks, e.g. to
// pick a per-worker region of a preallocated scratch buffer. Lock-free; a slot is always free as
// long as no more than num_slots chunks run at once (ParallelForChunks runs at most
// executor.num_threads()).
class SlotAllocator {
 public:
  explicit SlotAllocator(int num_slots) : num_slots_(num_slots) {
    ICEF_CHECK(num_slots >= 1 && num_slots <= 64, "SlotAllocator supports 1..64 slots");
  }
  int Acquire() {
    for (;;) {
      uint64_t used = used_.load(std::memory_order_relaxed);
      for (int i = 0; i < num_slots_; ++i) {
        const uint64_t bit = uint64_t{1} << i;
        if (!(used & bit) && used_.compare_exchange_weak(used, used | bit, std::memory_order_acquire))
          return i;
      }
    }
  }
  void Release(int slot) { used_.fetch_and(~(uint64_t{1} << slot), std::memory_order_release); }

  // RAII slot.
  class Slot {
   public:
    explicit Slot(SlotAllocator* a) : a_(a), index_(a->Acquire()) {}
    ~Slot() { a_->Release(index_); }
    Slot(const Slot&) = delete;
    Slot& operator=(const Slot&) = delete;
    int index() const { return index_; }

   private:
    SlotAllocator* a_;
    int index_;
  };

 private:
  int num_slots_;
  std::atomic<uint64_t> used_{0};
};

}  // namespace icef::nn
