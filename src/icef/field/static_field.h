// The static canonical radiance field F_static(x_c, d) -> (rgb, sigma) of docs/design.md §2: a
// multiresolution hash grid over the aabb, a density MLP and a colour MLP fed with the density
// MLP's output and the spherical-harmonics encoding of the view direction. It never receives the
// expression beta (condition_dims = 0), which is what makes identity expression-invariant by
// construction; only the entangled `nerface` baseline sets condition_dims = B, appending beta to
// the density MLP's input.
//
//   features = HashGrid(aabb.Normalize(x_c))            [n, L*F]
//   h        = DensityMlp([features, beta?])            [n, geo]   (no output activation)
//   sigma    = exp(min(h_0 + bias, kMaxLogDensity))     [n]
//   rgb      = ColorMlp([h, SH_4(d)])                   [n, 3]     (sigmoid)
#pragma once

#include <optional>
#include <span>
#include <string>
#include <vector>

#include "icef/core/parallel.h"
#include "icef/core/status.h"
#include "icef/math/ray.h"
#include "icef/nn/aligned.h"
#include "icef/nn/hash_grid.h"
#include "icef/nn/mlp.h"
#include "icef/nn/parameter_store.h"

namespace icef {

struct StaticFieldOptions {
  // Hash grid over the aabb (positions are normalised to [0,1]^3 before lookup).
  nn::HashGridOptions grid;
  // Width of the density MLP's hidden layer.
  int density_hidden = 64;
  // Outputs of the density MLP (the first is log-density; all feed the colour MLP).
  int geo_features = 16;
  // Widths of the colour MLP's hidden layers.
  std::vector<int> color_hidden = {64, 64};
  // Spherical-harmonics degree of the view-direction encoding (degree^2 values).
  int sh_degree = 2;
  // Expression dimensions appended to the density MLP input (0 = no beta; nerface only).
  int condition_dims = 0;
  // Added to the log-density before exp: sigma = exp(h_0 + density_bias).
  float density_bias = -4.f;
  // Inference passes (renders, occupancy) in BF16 with FP32 sums (nn::MlpOptions::bf16_inference).
  bool bf16_inference = true;
  // Training passes in BF16 with FP32 sums (nn::MlpOptions::bf16_training).
  bool bf16_training = true;

  bool operator==(const StaticFieldOptions&) const = default;
  Status Validate() const;
  std::string ToString() const;
};

// Largest log-density before exp (keeps sigma finite).
inline constexpr float kMaxLogDensity = 15.f;

// Per-batch buffers; reused across batches (grows, never shrinks).
struct StaticFieldContext {
  int64_t n = 0;
  bool has_position_jacobian = false;
  bool color_all = true;                      // the last ForwardColor coloured every sample
  std::vector<int32_t> color_rows;            // else the samples it coloured, ascending
  nn::AlignedVector<float> unit_positions;    // [n, 3] in [0,1]^3
  nn::AlignedVector<float> density_input;     // [n, L*F + condition_dims]
  nn::AlignedVector<float> grid_jacobian;     // [n, L*F, 3] when positions need gradients
  nn::AlignedVector<float> density_output;    // [n, geo]
  nn::AlignedVector<float> color_input;       // [m, geo + sh] for the m coloured samples
  nn::AlignedVector<float> color_output;      // [m, 3] when not every sample is coloured
  nn::AlignedVector<float> grid_features;     // [n, L*F] (only when condition_dims > 0)
  nn::AlignedVector<float> d_color_input;     // [m, geo + sh]
  nn::AlignedVector<float> d_color_output;    // [m, 3] when not every sample is coloured
  nn::AlignedVector<float> d_density_output;  // [n, geo]
  nn::AlignedVector<float> d_density_input;   // [n, L*F + condition_dims]
  nn::AlignedVector<float> d_unit_positions;  // [n, 3]
  nn::MlpContext density_mlp;
  nn::MlpContext color_mlp;
};

class StaticField {
 public:
  // Registers "<name>/grid", "<name>/density", "<name>/color" in *store (grid in `grid_group`,
  // MLPs in `mlp_group`); the store must outlive the field.
  StaticField(const StaticFieldOptions& options, const Aabb& aabb, nn::ParameterStore* store,
              const std::string& name, int grid_group, int mlp_group);
  void Initialize(uint64_t seed);

  // positions [n, 3] canonical world frame; directions [n, 3] unit, world frame; condition
  // [n, condition_dims] or null when condition_dims = 0 -> sigma [n], rgb [n, 3].
  // keep_for_backward keeps what Backward needs; need_position_grad also keeps the grid's
  // Jacobian so Backward can return d/d positions.
  void Forward(const Executor& executor, int64_t n, const float* positions, const float* directions,
               const float* condition, float* sigma, float* rgb, StaticFieldContext* ctx,
               bool keep_for_backward, bool need_position_grad) const;
  // Forward in two steps, for a caller that picks the samples to colour by their density (training
  // colours only the samples its rays composite): ForwardDensity -> sigma [n]; then ForwardColor ->
  // rgb [n, 3] of the samples `rows` (ascending indices in [0, n); nullopt: all n), 0 elsewhere.
  // Backward then reads d_rgb at those rows alone. Forward = both, every sample coloured.
  void ForwardDensity(const Executor& executor, int64_t n, const float* positions, const float* condition,
                      float* sigma, StaticFieldContext* ctx, bool keep_for_backward,
                      bool need_position_grad) const;
  void ForwardColor(const Executor& executor, int64_t n, const float* directions,
                    std::optional<std::span<const int32_t>> rows, float* rgb, StaticFieldContext* ctx,
                    bool keep_for_backward) const;
  // After Forward(keep_for_backward), with its outputs sigma [n] and rgb [n, 3]: accumulates
  // parameter gradients into the store from d_sigma [n] and d_rgb [n, 3] (the rows ForwardColor
  // coloured); writes d_positions [n, 3] (world frame) unless null.
  void Backward(const Executor& executor, int64_t n, const float* sigma, const float* rgb,
                const float* d_sigma, const float* d_rgb, StaticFieldContext* ctx, float* d_positions);
  // Density only (occupancy-grid updates): positions [n, 3] -> sigma [n].
  void Density(const Executor& executor, int64_t n, const float* positions, const float* condition,
               float* sigma, StaticFieldContext* ctx) const;

  // Coarse-to-fine: level l's features are multiplied by weights[l] in [0, 1] (size L; empty =
  // all ones). Gradients are scaled alike, so a level at weight 0 is neither used nor trained.
  void SetLevelWeights(std::vector<float> weights);
  const std::vector<float>& level_weights() const { return level_weights_; }
  int num_levels() const { return options_.grid.num_levels; }

  const StaticFieldOptions& options() const { return options_; }
  const Aabb& aabb() const { return aabb_; }
  std::string ToString() const;

 private:
  void DensityForward(const Executor& executor, int64_t n, const float* positions, const float* condition,
                      StaticFieldContext* ctx, bool keep_for_backward, bool need_position_grad) const;

  void ScaleLevels(int64_t n, float* features) const;

  StaticFieldOptions options_;
  Aabb aabb_;
  std::vector<float> level_weights_;  // [L] or empty
  nn::HashGridEncoding grid_;
  nn::Mlp density_mlp_;
  nn::Mlp color_mlp_;
};

}  // namespace icef
