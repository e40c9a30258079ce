// Multiresolution hash encoding kernels (instant-ngp), templated on the scalar type.
//
// Level l has integer resolution R_l = round(base * b^l), b = (finest / base)^(1 / (L - 1)); its
// vertices are the integer points 0..R_l of each axis. A position p in [0,1]^3 (clamped) maps to
// x = p * R_l, cell c = min(floor(x), R_l - 1), fraction f = x - c; the level's F features are the
// trilinear interpolation of the 8 cell corners' table entries. Corner v = c + (i, j, k) is
// indexed densely, v.x + v.y (R+1) + v.z (R+1)^2, when (R_l + 1)^3 <= T (the level then has
// (R_l + 1)^3 entries), else by the spatial hash (v.x * 1 ^ v.y * 2654435761 ^ v.z * 805459861)
// mod T (T entries). Table: level after level, each [entries, F] row-major, each level starting
// on a multiple of 8 entries (padding entries stay at their initial values and get no gradient).
// Features: [n, L * F], level-major (level l at columns l*F .. l*F+F-1).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

namespace icef::nn {

struct HashGridLevel {
  int resolution = 0;   // R_l: cells per axis
  bool dense = false;   // dense indexing (else hashed)
  int64_t offset = 0;   // first entry of the level in the table
  int64_t entries = 0;  // entries of the level
};

struct HashGridLayout {
  int num_levels = 0;
  int features = 0;         // F
  uint32_t table_size = 0;  // T (power of two)
  std::vector<HashGridLevel> levels;
  int64_t total_entries = 0;  // padding included
  int64_t num_params() const { return total_entries * features; }
  int output_dims() const { return num_levels * features; }
};

inline constexpr uint32_t kHashPrime1 = 2654435761u;
inline constexpr uint32_t kHashPrime2 = 805459861u;

// Level-local entry indices of the 8 cell corners (corner c: bit 0 = +x, bit 1 = +y, bit 2 = +z),
// the cell fractions, and per axis whether p was inside [0,1] (else clamped: zero derivative).
template <typename T>
inline void HashGridCell(const HashGridLevel& lv, uint32_t table_size, const T* p, uint32_t idx[8], T frac[3],
                         bool inside[3]) {
  const int r = lv.resolution;
  int cell[3];
  for (int a = 0; a < 3; ++a) {
    T q = p[a];
    inside[a] = q >= T(0) && q <= T(1);
    q = std::min(std::max(q, T(0)), T(1));
    const T x = q * T(r);
    int c = static_cast<int>(x);  // x >= 0: truncation is floor
    c = std::min(c, r - 1);
    cell[a] = c;
    frac[a] = x - T(c);
  }
  if (lv.dense) {
    const uint32_t s1 = static_cast<uint32_t>(r + 1), s2 = s1 * s1;
    const uint32_t base = static_cast<uint32_t>(cell[0]) + static_cast<uint32_t>(cell[1]) * s1 +
                          static_cast<uint32_t>(cell[2]) * s2;
    for (int c = 0; c < 8; ++c) {
      idx[c] = base + (c & 1 ? 1u : 0u) + (c & 2 ? s1 : 0u) + (c & 4 ? s2 : 0u);
    }
  } else {
    const uint32_t mask = table_size - 1;
    const uint32_t hx[2] = {static_cast<uint32_t>(cell[0]), static_cast<uint32_t>(cell[0] + 1)};
    const uint32_t hy[2] = {static_cast<uint32_t>(cell[1]) * kHashPrime1,
                            static_cast<uint32_t>(cell[1] + 1) * kHashPrime1};
    const uint32_t hz[2] = {static_cast<uint32_t>(cell[2]) * kHashPrime2,
                            static_cast<uint32_t>(cell[2] + 1) * kHashPrime2};
    for (int c = 0; c < 8; ++c) idx[c] = (hx[c & 1] ^ hy[(c >> 1) & 1] ^ hz[(c >> 2) & 1]) & mask;
  }
}

// Trilinear weights of the 8 corners.
template <typename T>
inline void TrilinearWeights(const T frac[3], T w[8]) {
  const T wx[2] = {T(1) - frac[0], frac[0]};
  const T wy[2] = {T(1) - frac[1], frac[1]};
  const T wz[2] = {T(1) - frac[2], frac[2]};
  for (int c = 0; c < 8; ++c) w[c] = wx[c & 1] * wy[(c >> 1) & 1] * wz[(c >> 2) & 1];
}

// positions [n, 3] -> features [n, L*F]. When d_features_d_positions is not null it also writes
// the Jacobian [n, L*F, 3] (d feature / d position), for a cheap BackwardInput later.
template <typename T>
void HashGridForward(const HashGridLayout& g, const T* table, int64_t n, const T* positions, T* features,
                     T* d_features_d_positions) {
  const int F = g.features;
  const int out = g.output_dims();
  for (int64_t s = 0; s < n; ++s) {
    const T* p = positions + 3 * s;
    T* f = features + s * out;
    T* jac = d_features_d_positions ? d_features_d_positions + s * out * 3 : nullptr;
    for (int l = 0; l < g.num_levels; ++l) {
      const HashGridLevel& lv = g.levels[l];
      uint32_t idx[8];
      T frac[3];
      bool inside[3];
      HashGridCell(lv, g.table_size, p, idx, frac, inside);
      T w[8];
      TrilinearWeights(frac, w);
      const T* tl = table + lv.offset * F;
      for (int k = 0; k < F; ++k) {
        T acc = T(0);
        for (int c = 0; c < 8; ++c) acc += w[c] * tl[int64_t{idx[c]} * F + k];
        f[l * F + k] = acc;
      }
      if (jac) {
        const T wx[2] = {T(1) - frac[0], frac[0]};
        const T wy[2] = {T(1) - frac[1], frac[1]};
        const T wz[2] = {T(1) - frac[2], frac[2]};
        const T r = T(lv.resolution);
        for (int k = 0; k < F; ++k) {
          T dx = T(0), dy = T(0), dz = T(0);
          for (int c = 0; c < 8; ++c) {
            const T v = tl[int64_t{idx[c]} * F + k];
            const int bx = c & 1, by = (c >> 1) & 1, bz = (c >> 2) & 1;
            const T sx = bx ? T(1) : T(-1), sy = by ? T(1) : T(-1), sz = bz ? T(1) : T(-1);
            dx += v * sx * wy[by] * wz[bz];
            dy += v * sy * wx[bx] * wz[bz];
            dz += v * sz * wx[bx] * wy[by];
          }
          T* j = jac + (l * F + k) * 3;
          j[0] = inside[0] ? dx * r : T(0);
          j[1] = inside[1] ? dy * r : T(0);
          j[2] = inside[2] ? dz * r : T(0);
        }
      }
    }
  }
}

// ACCUMULATES d loss / d table for levels [level_begin, level_end), samples in index order.
template <typename T>
void HashGridBackwardParams(const HashGridLayout& g, int64_t n, const T* positions, const T* d_features,
                            T* d_table, int level_begin, int level_end) {
  const int F = g.features;
  const int out = g.output_dims();
  for (int64_t s = 0; s < n; ++s) {
    const T* p = positions + 3 * s;
    const T* df = d_features + s * out;
    for (int l = level_begin; l < level_end; ++l) {
      const HashGridLevel& lv = g.levels[l];
      uint32_t idx[8];
      T frac[3];
      bool inside[3];
      HashGridCell(lv, g.table_size, p, idx, frac, inside);
      T w[8];
      TrilinearWeights(frac, w);
      T* tl = d_table + lv.offset * F;
      for (int c = 0; c < 8; ++c)
        for (int k = 0; k < F; ++k) tl[int64_t{idx[c]} * F + k] += w[c] * df[l * F + k];
    }
  }
}

// d_positions [n, 3] (overwritten) = Jacobian^T d_features, Jacobian from HashGridForward.
template <typename T>
void HashGridBackwardInput(const HashGridLayout& g, int64_t n, const T* d_features_d_positions,
                           const T* d_features, T* d_positions) {
  const int out = g.output_dims();
  for (int64_t s = 0; s < n; ++s) {
    const T* jac = d_features_d_positions + s * out * 3;
    const T* df = d_features + s * out;
    T a0 = T(0), a1 = T(0), a2 = T(0);
    for (int i = 0; i < out; ++i) {
      a0 += jac[3 * i] * df[i];
      a1 += jac[3 * i + 1] * df[i];
      a2 += jac[3 * i + 2] * df[i];
    }
    d_positions[3 * s] = a0;
    d_positions[3 * s + 1] = a1;
    d_positions[3 * s + 2] = a2;
  }
}

}  // namespace icef::nn
