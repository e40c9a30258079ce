// Adam over the flat parameter slab, with per-group hyper-parameters (a block's group index from
// ParameterStore::Register selects its AdamGroup) and a learning-rate schedule shared by all groups.
//
// Update (step t = 1, 2, ...; g the gradient; lr_t = lr * schedule(t)):
//   m = b1 m + (1 - b1) g;  v = b2 v + (1 - b2) g^2
//   p -= lr_t * (m / (1 - b1^t)) / (sqrt(v / (1 - b2^t)) + eps)  +  lr_t * weight_decay * p
// (decoupled weight decay, AdamW). Groups marked `sparse` (hash tables) are updated lazily: an
// entry whose gradient is exactly zero this step is skipped entirely (moments not decayed,
// parameter not moved), as torch.optim.SparseAdam / instant-ngp do; bias correction uses the
// global step. Step() zeroes the gradients it consumed, so no separate ZeroGrads pass is needed.
// Elementwise and split over threads in dynamic chunks: bit-identical for any thread count.
//
// Serialisation: magic "ICEFADM\0", u32 version (=1), i64 step, i64 slab size, then m and v.
#pragma once

#include <cstdint>
#include <iosfwd>
#include <string>
#include <vector>

#include "icef/core/parallel.h"
#include "icef/core/status.h"
#include "icef/nn/aligned.h"
#include "icef/nn/parameter_store.h"

namespace icef::nn {

struct AdamGroup {
  // Learning rate before the schedule.
  double learning_rate = 1e-3;
  // First-moment decay.
  double beta1 = 0.9;
  // Second-moment decay.
  double beta2 = 0.99;
  // Denominator epsilon.
  double epsilon = 1e-15;
  // Decoupled weight decay (0 = off).
  double weight_decay = 0.0;
  // Skip entries whose gradient is exactly zero this step (hash tables).
  bool sparse = false;

  Status Validate() const;
  std::string ToString() const;
};

enum class LrSchedule { kConstant, kStep, kExponential };

struct AdamOptions {
  // Hyper-parameters per parameter group (index = ParamBlock::group).
  std::vector<AdamGroup> groups = {AdamGroup{}};
  // Learning-rate schedule: constant; step: lr * decay_rate^floor(t / decay_steps);
  // exponential: lr * decay_rate^(t / decay_steps).
  LrSchedule schedule = LrSchedule::kConstant;
  // Decay factor per decay_steps steps.
  double decay_rate = 0.1;
  // Steps per decay_rate factor.
  int64_t decay_steps = 10000;

  Status Validate() const;
  std::string ToString() const;
};

class Adam {
 public:
  // Moments sized to the store's current slab; register every block before constructing.
  Adam(const AdamOptions& options, ParameterStore* store);

  // One update of every block from the store's gradients; zeroes those gradients.
  void Step(const Executor& executor);

  int64_t step() const { return step_; }
  // Schedule multiplier for step t.
  double ScheduleFactor(int64_t t) const;
  const AdamOptions& options() const { return options_; }
  void set_options(const AdamOptions& options);

  Status Write(std::ostream& out) const;
  Status Read(std::istream& in);
  std::string ToString() const;

 private:
  AdamOptions options_;
  ParameterStore* store_;
  int64_t step_ = 0;
  AlignedVector<float> m_;
  AlignedVector<float> v_;
};

}  // namespace icef::nn
