// Float fast paths of the hash encoding for F = 2 (the reference configuration), used by
// HashGridEncoding when features_per_level == 2. Same maths as hash_grid_kernels.h (the tests
// compare them), organised for memory-level parallelism: within a tile, level after level, the
// corner indices of all samples are computed first and their table lines prefetched, then
// gathered (forward) or updated (gradient scatter).
#pragma once

#include <cstdint>

#include "icef/nn/hash_grid_kernels.h"

namespace icef::nn {

// Samples per level pass (index/prefetch batch) of the fast paths.
inline constexpr int64_t kHashGridBatch = 64;

// As HashGridForward<float> for F == 2; n any size (processed in batches of kHashGridBatch).
void HashGridForwardF2(const HashGridLayout& g, const float* table, int64_t n, const float* positions,
                       float* features, float* d_features_d_positions);

// As HashGridBackwardParams<float> for F == 2 and ONE level, with the level's feature gradients
// given level-major: d_level [n, 2] (column pair l of the [n, L*2] sample-major matrix). d_level
// may equally point into a sample-major matrix with d_stride = L*2.
void HashGridScatterLevelF2(const HashGridLayout& g, int level, int64_t n, const float* positions,
                            const float* d_level, int64_t d_stride, float* d_table);

}  // namespace icef::nn
