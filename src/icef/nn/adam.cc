#include "icef/nn/adam.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <istream>
#include <ostream>
#include <sstream>

namespace icef::nn {

namespace {
constexpr char kMagic[8] = {'I', 'C', 'E', 'F', 'A', 'D', 'M', '\0'};
constexpr uint32_t kVersion = 1;
constexpr int64_t kAdamChunk = 1 << 16;

// Branch-free so the compiler vectorises it (AVX-512 masked blends for the sparse case).
template <bool kSparse>
void UpdateRange(float* __restrict p, float* __restrict g, float* __restrict m, float* __restrict v,
                 int64_t n, float lr, float b1, float b2, float c1, float c2, float eps, float wd) {
#pragma omp simd
  for (int64_t i = 0; i < n; ++i) {
    const float gi = g[i];
    const float mi = b1 * m[i] + (1.0f - b1) * gi;
    const float vi = b2 * v[i] + (1.0f - b2) * gi * gi;
    const float pi = p[i] - (lr * (mi * c1) / (std::sqrt(vi * c2) + eps) + lr * wd * p[i]);
    if (kSparse) {
      const bool touched = gi != 0.0f;
      m[i] = touched ? mi : m[i];
      v[i] = touched ? vi : v[i];
      p[i] = touched ? pi : p[i];
    } else {
      m[i] = mi;
      v[i] = vi;
      p[i] = pi;
    }
    g[i] = 0.0f;
  }
}
}  // namespace

Status AdamGroup::Validate() const {
  if (!(learning_rate >= 0.0) || !std::isfinite(learning_rate))
    return Status::Error("adam.learning_rate: must be finite and >= 0");
  if (!(beta1 >= 0.0 && beta1 < 1.0)) return Status::Error("adam.beta1: must be in [0, 1)");
  if (!(beta2 >= 0.0 && beta2 < 1.0)) return Status::Error("adam.beta2: must be in [0, 1)");
  if (!(epsilon >= 0.0)) return Status::Error("adam.epsilon: must be >= 0");
  if (!(weight_decay >= 0.0)) return Status::Error("adam.weight_decay: must be >= 0");
  return Status::Ok();
}

std::string AdamGroup::ToString() const {
  std::ostringstream s;
  s << "AdamGroup(lr=" << learning_rate << ", betas=" << beta1 << "/" << beta2 << ", eps=" << epsilon
    << ", wd=" << weight_decay << ", sparse=" << (sparse ? "true" : "false") << ")";
  return s.str();
}

Status AdamOptions::Validate() const {
  if (groups.empty()) return Status::Error("adam.groups: need at least one group");
  for (size_t i = 0; i < groups.size(); ++i) {
    const Status st = groups[i].Validate();
    if (!st.ok()) return st.WithContext("adam.groups[" + std::to_string(i) + "]");
  }
  if (!(decay_rate > 0.0)) return Status::Error("adam.decay_rate: must be > 0");
  if (decay_steps < 1) return Status::Error("adam.decay_steps: must be >= 1");
  return Status::Ok();
}

std::string AdamOptions::ToString() const {
  std::ostringstream s;
  s << "AdamOptions(schedule="
    << (schedule == LrSchedule::kConstant ? "constant"
        : schedule == LrSchedule::kStep   ? "step"
                                          : "exponential")
    << ", decay_rate=" << decay_rate << ", decay_steps=" << decay_steps;
  for (const AdamGroup& g : groups) s << ", " << g.ToString();
  s << ")";
  return s.str();
}

Adam::Adam(const AdamOptions& options, ParameterStore* store) : store_(store) {
  set_options(options);
  m_.assign(static_cast<size_t>(store->size()), 0.0f);
  v_.assign(static_cast<size_t>(store->size()), 0.0f);
}

void Adam::set_options(const AdamOptions& options) {
  const Status st = options.Validate();
  ICEF_CHECK(st.ok(), st.message());
  options_ = options;
}

double Adam::ScheduleFactor(int64_t t) const {
  switch (options_.schedule) {
    case LrSchedule::kConstant:
      return 1.0;
    case LrSchedule::kStep:
      return std::pow(options_.decay_rate, static_cast<double>(t / options_.decay_steps));
    case LrSchedule::kExponential:
      return std::pow(options_.decay_rate,
                      static_cast<double>(t) / static_cast<double>(options_.decay_steps));
  }
  return 1.0;
}

void Adam::Step(const Executor& executor) {
  ICEF_CHECK(static_cast<int64_t>(m_.size()) == store_->size(),
             "Adam: the parameter store grew after the optimiser was built");
  ++step_;
  const double sched = ScheduleFactor(step_);
  for (const ParamBlock& b : store_->blocks()) {
    ICEF_CHECK(b.group >= 0 && b.group < static_cast<int>(options_.groups.size()),
               "Adam: block " + b.name + " has group " + std::to_string(b.group) + " without settings");
    const AdamGroup& g = options_.groups[b.group];
    const float lr = static_cast<float>(g.learning_rate * sched);
    const float c1 = static_cast<float>(1.0 / (1.0 - std::pow(g.beta1, static_cast<double>(step_))));
    const float c2 = static_cast<float>(1.0 / (1.0 - std::pow(g.beta2, static_cast<double>(step_))));
    float* p = store_->params() + b.offset;
    float* gr = store_->grads() + b.offset;
    float* m = m_.data() + b.offset;
    float* v = v_.data() + b.offset;
    const float b1 = static_cast<float>(g.beta1), b2 = static_cast<float>(g.beta2);
    const float eps = static_cast<float>(g.epsilon), wd = static_cast<float>(g.weight_decay);
    // Elementwise, so dynamic chunks are deterministic; small blocks stay on the caller.
    const Executor serial(1);
    const Executor& ex = b.size >= 2 * kAdamChunk ? executor : serial;
    ParallelForChunks(ex, b.size, kAdamChunk, [&](int64_t begin, int64_t end) {
      if (g.sparse) {
        UpdateRange<true>(p + begin, gr + begin, m + begin, v + begin, end - begin, lr, b1, b2, c1, c2, eps,
                          wd);
      } else {
        UpdateRange<false>(p + begin, gr + begin, m + begin, v + begin, end - begin, lr, b1, b2, c1, c2, eps,
                           wd);
      }
    });
  }
}

Status Adam::Write(std::ostream& out) const {
  out.write(kMagic, sizeof(kMagic));
  out.write(reinterpret_cast<const char*>(&kVersion), sizeof(kVersion));
  const int64_t size = static_cast<int64_t>(m_.size());
  out.write(reinterpret_cast<const char*>(&step_), sizeof(step_));
  out.write(reinterpret_cast<const char*>(&size), sizeof(size));
  out.write(reinterpret_cast<const char*>(m_.data()), static_cast<std::streamsize>(size * sizeof(float)));
  out.write(reinterpret_cast<const char*>(v_.data()), static_cast<std::streamsize>(size * sizeof(float)));
  if (!out) return Status::Error("optimiser: write failed");
  return Status::Ok();
}

Status Adam::Read(std::istream& in) {
  char magic[8];
  in.read(magic, sizeof(magic));
  if (!in || std::memcmp(magic, kMagic, sizeof(kMagic)) != 0) {
    return Status::Error("optimiser: bad magic (not an ICEF Adam section)");
  }
  uint32_t version = 0;
  in.read(reinterpret_cast<char*>(&version), sizeof(version));
  if (!in) return Status::Error("optimiser: truncated header (version)");
  if (version != kVersion) {
    return Status::Error("optimiser: unsupported version " + std::to_string(version) + " (expected " +
                         std::to_string(kVersion) + ")");
  }
  int64_t step = 0, size = 0;
  in.read(reinterpret_cast<char*>(&step), sizeof(step));
  in.read(reinterpret_cast<char*>(&size), sizeof(size));
  if (!in) return Status::Error("optimiser: truncated header (step, size)");
  if (size != static_cast<int64_t>(m_.size())) {
    return Status::Error("optimiser: state has " + std::to_string(size) + " floats, model slab has " +
                         std::to_string(m_.size()));
  }
  if (step < 0) return Status::Error("optimiser: negative step " + std::to_string(step));
  in.read(reinterpret_cast<char*>(m_.data()), static_cast<std::streamsize>(size * sizeof(float)));
  in.read(reinterpret_cast<char*>(v_.data()), static_cast<std::streamsize>(size * sizeof(float)));
  if (!in) return Status::Error("optimiser: truncated moment data");
  step_ = step;
  return Status::Ok();
}

std::string Adam::ToString() const {
  return "Adam(step=" + std::to_string(step_) + ", " + options_.ToString() + ")";
}

}  // namespace icef::nn
