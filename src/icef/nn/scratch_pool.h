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
