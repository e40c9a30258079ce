#include "icef/nn/hash_grid_fast.h"

#include <algorithm>
#include <cstring>

namespace icef::nn {

namespace {

struct Corners {
  uint32_t idx[8];
  float frac[3];
  bool inside[3];
};

inline void Prefetch(const float* p) { __builtin_prefetch(p, 0, 3); }
inline void PrefetchWrite(const float* p) { __builtin_prefetch(p, 1, 3); }

// Corner indices of sample i at level lv, with the table lines prefetched.
inline void LocateAndPrefetch(const HashGridLayout& g, const HashGridLevel& lv, const float* tl,
                              const float* p, Corners* c) {
  HashGridCell<float>(lv, g.table_size, p, c->idx, c->frac, c->inside);
  for (int k = 0; k < 8; ++k) Prefetch(tl + 2 * int64_t{c->idx[k]});
}

// Interpolates level features (and their position Jacobian) from located corners.
inline void Interpolate(const float* tl, const Corners& c, float r, float* f, float* j) {
  float v[8][2];
  for (int k = 0; k < 8; ++k) std::memcpy(v[k], tl + 2 * int64_t{c.idx[k]}, 2 * sizeof(float));
  const float fx = c.frac[0], fy = c.frac[1], fz = c.frac[2];
  for (int k = 0; k < 2; ++k) {
    // Corner order: bit 0 = +x, bit 1 = +y, bit 2 = +z.
    const float e00 = v[1][k] - v[0][k], e10 = v[3][k] - v[2][k];
    const float e01 = v[5][k] - v[4][k], e11 = v[7][k] - v[6][k];
    const float l00 = v[0][k] + fx * e00, l10 = v[2][k] + fx * e10;
    const float l01 = v[4][k] + fx * e01, l11 = v[6][k] + fx * e11;
    const float ey0 = l10 - l00, ey1 = l11 - l01;
    const float m0 = l00 + fy * ey0, m1 = l01 + fy * ey1;
    f[k] = m0 + fz * (m1 - m0);
    if (j) {
      const float wy0 = 1.0f - fy, wz0 = 1.0f - fz;
      const float dfx = wz0 * (wy0 * e00 + fy * e10) + fz * (wy0 * e01 + fy * e11);
      const float dfy = wz0 * ey0 + fz * ey1;
      const float dfz = m1 - m0;
      j[3 * k] = c.inside[0] ? dfx * r : 0.0f;
      j[3 * k + 1] = c.inside[1] ? dfy * r : 0.0f;
      j[3 * k + 2] = c.inside[2] ? dfz * r : 0.0f;
    }
  }
}

}  // namespace

void HashGridForwardF2(const HashGridLayout& g, const float* table, int64_t n, const float* positions,
                       float* features, float* jac) {
  // Software pipeline: while level l's corners are gathered, level l+1's are located and their
  // lines prefetched, so the memory system always has requests in flight.
  const int out = g.output_dims();
  const int levels = g.num_levels;
  Corners corners[2][kHashGridBatch];
  for (int64_t s0 = 0; s0 < n; s0 += kHashGridBatch) {
    const int64_t m = std::min(kHashGridBatch, n - s0);
    const float* pos = positions + 3 * s0;
    {
      const float* tl0 = table + g.levels[0].offset * 2;
      for (int64_t i = 0; i < m; ++i) LocateAndPrefetch(g, g.levels[0], tl0, pos + 3 * i, &corners[0][i]);
    }
    for (int l = 0; l < levels; ++l) {
      const Corners* cur = corners[l & 1];
      Corners* next = corners[(l + 1) & 1];
      const float* tl = table + g.levels[l].offset * 2;
      const float r = static_cast<float>(g.levels[l].resolution);
      const bool has_next = l + 1 < levels;
      const float* tn = has_next ? table + g.levels[l + 1].offset * 2 : nullptr;
      for (int64_t i = 0; i < m; ++i) {
        if (has_next) LocateAndPrefetch(g, g.levels[l + 1], tn, pos + 3 * i, &next[i]);
        float* f = features + (s0 + i) * out + 2 * l;
        float* j = jac ? jac + ((s0 + i) * out + 2 * l) * 3 : nullptr;
        Interpolate(tl, cur[i], r, f, j);
      }
    }
  }
}

void HashGridScatterLevelF2(const HashGridLayout& g, int level, int64_t n, const float* positions,
                            const float* d_level, int64_t d_stride, float* d_table) {
  // Pipelined like the forward pass: batch b+1 is located (lines prefetched for writing) while
  // batch b is scattered. Samples are applied in index order.
  const HashGridLevel& lv = g.levels[level];
  float* tl = d_table + lv.offset * 2;
  Corners corners[2][kHashGridBatch];
  auto locate = [&](int64_t s0, Corners* out) {
    const int64_t m = std::min(kHashGridBatch, n - s0);
    for (int64_t i = 0; i < m; ++i) {
      HashGridCell<float>(lv, g.table_size, positions + 3 * (s0 + i), out[i].idx, out[i].frac, out[i].inside);
      for (int k = 0; k < 8; ++k) PrefetchWrite(tl + 2 * int64_t{out[i].idx[k]});
    }
  };
  if (n > 0) locate(0, corners[0]);
  int buf = 0;
  for (int64_t s0 = 0; s0 < n; s0 += kHashGridBatch, buf ^= 1) {
    const int64_t m = std::min(kHashGridBatch, n - s0);
    if (s0 + kHashGridBatch < n) locate(s0 + kHashGridBatch, corners[buf ^ 1]);
    for (int64_t i = 0; i < m; ++i) {
      const Corners& c = corners[buf][i];
      const float* d = d_level + (s0 + i) * d_stride;
      const float d0 = d[0], d1 = d[1];
      float w[8];
      TrilinearWeights<float>(c.frac, w);
      for (int k = 0; k < 8; ++k) {
        float* e = tl + 2 * int64_t{c.idx[k]};
        e[0] += w[k] * d0;
        e[1] += w[k] * d1;
      }
    }
  }
}

}  // namespace icef::nn
