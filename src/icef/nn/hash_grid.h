// Multiresolution hash encoding (instant-ngp), float32 tables in a ParameterStore block. See
// hash_grid_kernels.h for the exact resolution, indexing and interpolation rules.
//
// Frames and shapes: positions [n, 3] are NORMALISED canonical coordinates in [0,1]^3 (the caller
// maps its aabb onto the unit cube; values outside are clamped and get zero input gradient);
// features [n, L*F], level-major. Initial table values: U(-init_scale, init_scale) (instant-ngp
// uses 1e-4), drawn from Rng(seed, "hash_grid_init", block index).
#pragma once

#include <cstdint>
#include <string>

#include "icef/core/parallel.h"
#include "icef/core/status.h"
#include "icef/nn/hash_grid_kernels.h"
#include "icef/nn/parameter_store.h"

namespace icef::nn {

struct HashGridOptions {
  // Number of resolution levels L.
  int num_levels = 16;
  // Features per level F.
  int features_per_level = 2;
  // log2 of the hashed table size T per level.
  int log2_table_size = 16;
  // Resolution of the coarsest level (cells per axis).
  double base_resolution = 16.0;
  // Resolution of the finest level; levels grow geometrically in between.
  double finest_resolution = 512.0;
  // Initial table values are uniform in [-init_scale, init_scale].
  float init_scale = 1e-4f;

  bool operator==(const HashGridOptions&) const = default;
  Status Validate() const;
  std::string ToString() const;
};

// docs/design.md §7's reference configuration (instant-ngp's: T = 2^19, finest resolution 1024), which
// the engine's kernel benchmarks use; the avatar's default grid is smaller.
inline HashGridOptions ReferenceHashGridOptions() {
  HashGridOptions o;
  o.log2_table_size = 19;
  o.finest_resolution = 1024.0;
  return o;
}

// Resolutions, indexing mode and table offsets of every level.
HashGridLayout MakeHashGridLayout(const HashGridOptions& options);

class HashGridEncoding {
 public:
  // Registers block `name` (group `group`) in *store; the store must outlive the encoding.
  HashGridEncoding(const HashGridOptions& options, ParameterStore* store, const std::string& name,
                   int group = 0);

  void Initialize(uint64_t seed);

  const HashGridOptions& options() const { return options_; }
  const HashGridLayout& layout() const { return layout_; }
  int input_dims() const { return 3; }
  int output_dims() const { return layout_.output_dims(); }
  int64_t num_params() const { return layout_.num_params(); }
  int block_index() const { return block_; }
  const float* table() const { return store_->params(block_).data(); }
  float* table() { return store_->params(block_).data(); }
  float* table_grads() { return store_->grads(block_).data(); }

  // positions [n, 3] in [0,1]^3 -> features [n, L*F]; d_features_d_positions [n, L*F, 3] is
  // written too unless null (needed by BackwardInput).
  void Forward(const Executor& executor, int64_t n, const float* positions, float* features,
               float* d_features_d_positions = nullptr) const;

  // ACCUMULATES d loss / d table into the store's gradient block from d_features [n, L*F].
  // Levels are handed to threads one at a time and each level sees the samples in index order,
  // so the result is bit-identical for ANY thread count and scheduling.
  void BackwardParams(const Executor& executor, int64_t n, const float* positions, const float* d_features);

  // d_positions [n, 3] (overwritten) from d_features [n, L*F] and the forward Jacobian.
  void BackwardInput(const Executor& executor, int64_t n, const float* d_features_d_positions,
                     const float* d_features, float* d_positions) const;

  // Single-thread tile versions for fused pipelines (same contracts as above).
  void ForwardTile(int64_t n, const float* positions, float* features, float* d_features_d_positions) const;
  void BackwardParamsLevels(int64_t n, const float* positions, const float* d_features, int level_begin,
                            int level_end);
  // One level's table gradient from that level's feature gradients d_level (row s at
  // d_level + s * d_stride, F values): d_stride = L*F with d_level = d_features + l*F reads a
  // sample-major matrix; d_stride = F reads a level-major buffer [n, F] (cheaper to stream).
  void BackwardParamsLevel(int level, int64_t n, const float* positions, const float* d_level,
                           int64_t d_stride);

  std::string ToString() const;

 private:
  HashGridOptions options_;
  HashGridLayout layout_;
  ParameterStore* store_;
  int block_;
};

}  // namespace icef::nn
