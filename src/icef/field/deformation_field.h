// The expression-conditioned deformation field of docs/design.md §2:
//   D_phi(x, beta) = x + g_phi(enc(x_u), beta),   x_u = 2 (x - aabb.min) / aabb.extent - 1
// an observation-space point x (world frame) maps to canonical space for expression beta. enc is a
// frequency encoding of x_u (coarse-to-fine annealing via SetAnnealing), g an MLP whose output is
// in half-extent units of the aabb (offset_world = g * extent / 2), initialised near zero so the
// warp starts as the identity.
//
// The linearised deformation around the nearest observed expression beta_n,
//   D_lin(x, beta) = D_phi(x, beta_n) + J_beta D_phi(x, beta_n) (beta - beta_n),
// is computed exactly by the engine's forward-mode JVP (never by finite differences).
#pragma once

#include <string>
#include <vector>

#include "icef/core/parallel.h"
#include "icef/core/status.h"
#include "icef/math/ray.h"
#include "icef/nn/frequency_mlp.h"
#include "icef/nn/parameter_store.h"

namespace icef {

struct DeformationFieldOptions {
  // Frequencies of the positional encoding of x_u (2^0 .. 2^(N-1), times pi).
  int num_frequencies = 6;
  // Hidden widths of the MLP g.
  std::vector<int> hidden = {64, 64, 64};
  // Scale of the initial output-layer weights (small: the warp starts near the identity).
  float output_init_scale = 1e-2f;
  // Inference passes (renders, occupancy) in BF16 with FP32 sums (nn::MlpOptions::bf16_inference).
  bool bf16_inference = true;
  // Training passes in BF16 with FP32 sums (nn::MlpOptions::bf16_training).
  bool bf16_training = true;

  bool operator==(const DeformationFieldOptions&) const = default;
  Status Validate() const;
  std::string ToString() const;
};

struct DeformationContext {
  int64_t n = 0;
  nn::AlignedVector<float> unit_positions;  // [n, 3]
  nn::AlignedVector<float> raw;             // [n, 3] MLP output (half-extent units)
  nn::AlignedVector<float> d_raw;           // [n, 3]
  nn::AlignedVector<float> tangent;         // [n, 3] JVP output
  nn::FrequencyMlpContext mlp;
};

class DeformationField {
 public:
  // Registers "<name>" in *store (group `group`).
  DeformationField(const DeformationFieldOptions& options, int expression_dims, const Aabb& aabb,
                   nn::ParameterStore* store, const std::string& name, int group);
  void Initialize(uint64_t seed);

  // Coarse-to-fine: alpha in [0, num_frequencies] (num_frequencies = all frequencies on).
  void SetAnnealing(double alpha);
  double annealing() const { return mlp_.encoding().alpha(); }

  // positions [n, 3] world frame, betas [n, B] -> offsets [n, 3] world frame (D = x + offset).
  void Forward(const Executor& executor, int64_t n, const float* positions, const float* betas,
               float* offsets, DeformationContext* ctx, bool keep_for_backward) const;
  // After Forward(keep_for_backward): accumulates parameter gradients from d_offsets [n, 3]
  // (world frame). Positions are data, so no input gradient is produced.
  void Backward(const Executor& executor, int64_t n, const float* d_offsets, DeformationContext* ctx);
  // Linearised offsets: offsets = g(x, beta_n) + J_beta g(x, beta_n) (beta - beta_n), world frame;
  // anchors = beta_n rows [n, B],
  // directions = (beta - beta_n) rows [n, B].
  void LinearizedForward(const Executor& executor, int64_t n, const float* positions, const float* anchors,
                         const float* directions, float* offsets, DeformationContext* ctx) const;

  int expression_dims() const { return expression_dims_; }
  const DeformationFieldOptions& options() const { return options_; }
  std::string ToString() const;

 private:
  void ToUnit(const Executor& executor, int64_t n, const float* positions, DeformationContext* ctx) const;

  DeformationFieldOptions options_;
  int expression_dims_;
  Aabb aabb_;
  Vec3f half_extent_;
  nn::FrequencyMlp mlp_;
};

}  // namespace icef
