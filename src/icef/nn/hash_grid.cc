#include "icef/nn/hash_grid.h"

#include <cmath>
#include <sstream>

#include "icef/core/rng.h"
#include "icef/nn/hash_grid_fast.h"

namespace icef::nn {

Status HashGridOptions::Validate() const {
  if (num_levels < 1 || num_levels > 64) return Status::Error("hash_grid.num_levels: must be in [1, 64]");
  if (features_per_level < 1 || features_per_level > 8) {
    return Status::Error("hash_grid.features_per_level: must be in [1, 8]");
  }
  if (log2_table_size < 4 || log2_table_size > 30) {
    return Status::Error("hash_grid.log2_table_size: must be in [4, 30]");
  }
  if (!(base_resolution >= 1.0)) return Status::Error("hash_grid.base_resolution: must be >= 1");
  if (!(finest_resolution >= base_resolution) || finest_resolution > 1e6) {
    return Status::Error("hash_grid.finest_resolution: must be in [base_resolution, 1e6]");
  }
  if (!(init_scale >= 0.0f)) return Status::Error("hash_grid.init_scale: must be >= 0");
  return Status::Ok();
}

std::string HashGridOptions::ToString() const {
  std::ostringstream s;
  s << "HashGridOptions(L=" << num_levels << ", F=" << features_per_level << ", log2_T=" << log2_table_size
    << ", base=" << base_resolution << ", finest=" << finest_resolution << ", init_scale=" << init_scale
    << ")";
  return s.str();
}

HashGridLayout MakeHashGridLayout(const HashGridOptions& o) {
  HashGridLayout g;
  g.num_levels = o.num_levels;
  g.features = o.features_per_level;
  g.table_size = 1u << o.log2_table_size;
  const double growth = o.num_levels > 1
                            ? std::exp(std::log(o.finest_resolution / o.base_resolution) / (o.num_levels - 1))
                            : 1.0;
  int64_t offset = 0;
  for (int l = 0; l < o.num_levels; ++l) {
    HashGridLevel lv;
    lv.resolution = std::max(1, static_cast<int>(std::lround(o.base_resolution * std::pow(growth, l))));
    const double dense_entries = std::pow(static_cast<double>(lv.resolution) + 1.0, 3.0);
    lv.dense = dense_entries <= static_cast<double>(g.table_size);
    lv.entries = lv.dense ? static_cast<int64_t>(dense_entries) : int64_t{g.table_size};
    lv.offset = offset;
    // Levels start on 8-entry boundaries so that an x-neighbour pair (indices 2j, 2j+1) never
    // straddles a cache line when F = 2 (the padding entries are never addressed).
    offset += (lv.entries + 7) / 8 * 8;
    g.levels.push_back(lv);
  }
  g.total_entries = offset;
  return g;
}

HashGridEncoding::HashGridEncoding(const HashGridOptions& options, ParameterStore* store,
                                   const std::string& name, int group)
    : options_(options), store_(store) {
  const Status st = options.Validate();
  ICEF_CHECK(st.ok(), st.message());
  layout_ = MakeHashGridLayout(options);
  block_ = store_->Register(name, layout_.num_params(), group);
}

void HashGridEncoding::Initialize(uint64_t seed) {
  Rng rng(seed, StreamId("hash_grid_init"), static_cast<uint64_t>(block_));
  float* t = table();
  const double s = options_.init_scale;
  for (int64_t i = 0; i < num_params(); ++i) t[i] = static_cast<float>(rng.Uniform(-s, s));
}

void HashGridEncoding::ForwardTile(int64_t n, const float* positions, float* features,
                                   float* d_features_d_positions) const {
  if (layout_.features == 2) {
    HashGridForwardF2(layout_, table(), n, positions, features, d_features_d_positions);
  } else {
    HashGridForward<float>(layout_, table(), n, positions, features, d_features_d_positions);
  }
}

void HashGridEncoding::BackwardParamsLevel(int level, int64_t n, const float* positions, const float* d_level,
                                           int64_t d_stride) {
  ICEF_CHECK(level >= 0 && level < layout_.num_levels, "hash grid level out of range");
  if (layout_.features == 2) {
    HashGridScatterLevelF2(layout_, level, n, positions, d_level, d_stride, table_grads());
    return;
  }
  const HashGridLevel& lv = layout_.levels[level];
  const int F = layout_.features;
  float* tl = table_grads() + lv.offset * F;
  for (int64_t s = 0; s < n; ++s) {
    uint32_t idx[8];
    float frac[3], w[8];
    bool inside[3];
    HashGridCell<float>(lv, layout_.table_size, positions + 3 * s, idx, frac, inside);
    TrilinearWeights<float>(frac, w);
    const float* d = d_level + s * d_stride;
    for (int c = 0; c < 8; ++c)
      for (int k = 0; k < F; ++k) tl[int64_t{idx[c]} * F + k] += w[c] * d[k];
  }
}

void HashGridEncoding::BackwardParamsLevels(int64_t n, const float* positions, const float* d_features,
                                            int level_begin, int level_end) {
  for (int l = level_begin; l < level_end; ++l) {
    BackwardParamsLevel(l, n, positions, d_features + l * layout_.features, output_dims());
  }
}

void HashGridEncoding::Forward(const Executor& executor, int64_t n, const float* positions, float* features,
                               float* d_features_d_positions) const {
  const int out = output_dims();
  ParallelForChunks(executor, n, BalancedChunk(n, 64, 4096), [&](int64_t begin, int64_t end) {
    ForwardTile(end - begin, positions + 3 * begin, features + begin * out,
                d_features_d_positions ? d_features_d_positions + begin * out * 3 : nullptr);
  });
}

void HashGridEncoding::BackwardParams(const Executor& executor, int64_t n, const float* positions,
                                      const float* d_features) {
  // One level per work item, finest (hashed, most expensive) first, handed out dynamically.
  const int levels = layout_.num_levels;
  ParallelForChunks(executor, levels, 1, [&](int64_t begin, int64_t end) {
    for (int64_t i = begin; i < end; ++i) {
      const int l = levels - 1 - static_cast<int>(i);
      BackwardParamsLevels(n, positions, d_features, l, l + 1);
    }
  });
}

void HashGridEncoding::BackwardInput(const Executor& executor, int64_t n, const float* d_features_d_positions,
                                     const float* d_features, float* d_positions) const {
  const int out = output_dims();
  ParallelForChunks(executor, n, BalancedChunk(n, 64, 4096), [&](int64_t begin, int64_t end) {
    HashGridBackwardInput<float>(layout_, end - begin, d_features_d_positions + begin * out * 3,
                                 d_features + begin * out, d_positions + 3 * begin);
  });
}

std::string HashGridEncoding::ToString() const {
  std::ostringstream s;
  s << "HashGridEncoding(" << store_->block(block_).name << ", " << options_.ToString()
    << ", params=" << num_params() << ")";
  return s.str();
}

}  // namespace icef::nn
