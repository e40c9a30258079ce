#include "icef/nn/gemm.h"

#if defined(__AVX512F__) || (defined(__AVX2__) && defined(__FMA__))
#include <immintrin.h>
#endif

namespace icef::nn {

#if defined(__AVX512F__)
namespace {

// R rows of C, MV vectors of 16 columns each: R*MV accumulators live in zmm registers for the
// whole k loop. C[s, j] = sum_p A[s, p] B[p, j].
template <int R, int MV>
inline void NNBlock(int k, int m, const float* a, const float* b, float* c) {
  __m512 acc[R][MV];
  for (int r = 0; r < R; ++r)
    for (int v = 0; v < MV; ++v) acc[r][v] = _mm512_setzero_ps();
  for (int p = 0; p < k; ++p) {
    __m512 bv[MV];
    for (int v = 0; v < MV; ++v) bv[v] = _mm512_loadu_ps(b + static_cast<int64_t>(p) * m + 16 * v);
    for (int r = 0; r < R; ++r) {
      const __m512 av = _mm512_set1_ps(a[static_cast<int64_t>(r) * k + p]);
      for (int v = 0; v < MV; ++v) acc[r][v] = _mm512_fmadd_ps(av, bv[v], acc[r][v]);
    }
  }
  for (int r = 0; r < R; ++r)
    for (int v = 0; v < MV; ++v) _mm512_storeu_ps(c + static_cast<int64_t>(r) * m + 16 * v, acc[r][v]);
}

template <int R, int MV>
void NNPanel(int64_t n, int k, int m, const float* a, const float* b, float* c) {
  // m == 16 * MV * (number of column panels); columns handled in panels of 16*MV.
  for (int j0 = 0; j0 < m; j0 += 16 * MV) {
    int64_t s = 0;
    for (; s + R <= n; s += R) NNBlock<R, MV>(k, m, a + s * k, b + j0, c + s * m + j0);
    for (; s < n; ++s) NNBlock<1, MV>(k, m, a + s * k, b + j0, c + s * m + j0);
  }
}

// C[p, j] += sum_s A[s, p] B[s, j] for R rows p0..p0+R-1 and MV column vectors.
template <int R, int MV>
inline void TNBlock(int64_t n, int k, int m, const float* a, const float* b, float* c) {
  __m512 acc[R][MV];
  for (int r = 0; r < R; ++r)
    for (int v = 0; v < MV; ++v) acc[r][v] = _mm512_loadu_ps(c + static_cast<int64_t>(r) * m + 16 * v);
  for (int64_t s = 0; s < n; ++s) {
    __m512 bv[MV];
    for (int v = 0; v < MV; ++v) bv[v] = _mm512_loadu_ps(b + s * m + 16 * v);
    for (int r = 0; r < R; ++r) {
      const __m512 av = _mm512_set1_ps(a[s * k + r]);
      for (int v = 0; v < MV; ++v) acc[r][v] = _mm512_fmadd_ps(av, bv[v], acc[r][v]);
    }
  }
  for (int r = 0; r < R; ++r)
    for (int v = 0; v < MV; ++v) _mm512_storeu_ps(c + static_cast<int64_t>(r) * m + 16 * v, acc[r][v]);
}

template <int R, int MV>
void TNPanel(int64_t n, int k, int m, const float* a, const float* b, float* c) {
  for (int j0 = 0; j0 < m; j0 += 16 * MV) {
    int p = 0;
    for (; p + R <= k; p += R) TNBlock<R, MV>(n, k, m, a + p, b + j0, c + static_cast<int64_t>(p) * m + j0);
    for (; p < k; ++p) TNBlock<1, MV>(n, k, m, a + p, b + j0, c + static_cast<int64_t>(p) * m + j0);
  }
}

// Column tail of fewer than 16 columns (masked loads/stores), R rows at a time.
template <int R>
inline void NNBlockMasked(int k, int m, const float* a, const float* b, float* c, __mmask16 mask) {
  __m512 acc[R];
  for (int r = 0; r < R; ++r) acc[r] = _mm512_setzero_ps();
  for (int p = 0; p < k; ++p) {
    const __m512 bv = _mm512_maskz_loadu_ps(mask, b + static_cast<int64_t>(p) * m);
    for (int r = 0; r < R; ++r) {
      acc[r] = _mm512_fmadd_ps(_mm512_set1_ps(a[static_cast<int64_t>(r) * k + p]), bv, acc[r]);
    }
  }
  for (int r = 0; r < R; ++r) _mm512_mask_storeu_ps(c + static_cast<int64_t>(r) * m, mask, acc[r]);
}

// C[n, m] = A[n, k] B[k, m] for m < 16 columns and k a multiple of 16 (the 3-wide output layers):
// vectorised along k, one dot product per (row, column) from the columns of B gathered once.
template <int KV>
void NNSmallM(int64_t n, int m, const float* a, const float* b, float* c) {
  constexpr int k = 16 * KV;
  __m512 bt[15][KV];
  alignas(64) float col[k];
  for (int j = 0; j < m; ++j) {
    for (int p = 0; p < k; ++p) col[p] = b[int64_t{p} * m + j];
    for (int v = 0; v < KV; ++v) bt[j][v] = _mm512_load_ps(col + 16 * v);
  }
  for (int64_t s = 0; s < n; ++s) {
    __m512 av[KV];
    for (int v = 0; v < KV; ++v) av[v] = _mm512_loadu_ps(a + s * k + 16 * v);
    for (int j = 0; j < m; ++j) {
      __m512 acc = _mm512_mul_ps(av[0], bt[j][0]);
      for (int v = 1; v < KV; ++v) acc = _mm512_fmadd_ps(av[v], bt[j][v], acc);
      c[s * m + j] = _mm512_reduce_add_ps(acc);
    }
  }
}

void NNTail(int64_t n, int k, int m, int j0, const float* a, const float* b, float* c) {
  const __mmask16 mask = static_cast<__mmask16>((1u << (m - j0)) - 1u);
  int64_t s = 0;
  for (; s + 12 <= n; s += 12) NNBlockMasked<12>(k, m, a + s * k, b + j0, c + s * m + j0, mask);
  for (; s < n; ++s) NNBlockMasked<1>(k, m, a + s * k, b + j0, c + s * m + j0, mask);
}

// C[k, m] += A[n, k]^T B[n, m] for small m (< 16) and k a multiple of 16: vectorised along k,
// C^T [m, k] accumulated in registers (m * k/16 accumulators), added transposed at the end.
template <int M, int KV>
void TNSmallM(int64_t n, const float* a, const float* b, float* c) {
  constexpr int k = 16 * KV;
  __m512 acc[M][KV];
  for (int j = 0; j < M; ++j)
    for (int v = 0; v < KV; ++v) acc[j][v] = _mm512_setzero_ps();
  for (int64_t s = 0; s < n; ++s) {
    __m512 av[KV];
    for (int v = 0; v < KV; ++v) av[v] = _mm512_loadu_ps(a + s * k + 16 * v);
    for (int j = 0; j < M; ++j) {
      const __m512 bj = _mm512_set1_ps(b[s * M + j]);
      for (int v = 0; v < KV; ++v) acc[j][v] = _mm512_fmadd_ps(bj, av[v], acc[j][v]);
    }
  }
  alignas(64) float tmp[M][k];
  for (int j = 0; j < M; ++j)
    for (int v = 0; v < KV; ++v) _mm512_store_ps(&tmp[j][16 * v], acc[j][v]);
  for (int p = 0; p < k; ++p)
    for (int j = 0; j < M; ++j) c[p * M + j] += tmp[j][p];
}

}  // namespace

template <>
void GemmNN<float>(int64_t n, int k, int m, const float* a, const float* b, float* c) {
  if (m % 64 == 0) return NNPanel<6, 4>(n, k, m, a, b, c);
  if (m % 32 == 0) return NNPanel<12, 2>(n, k, m, a, b, c);
  if (m % 16 == 0) return NNPanel<16, 1>(n, k, m, a, b, c);
  if (m < 16 && k == 64) return NNSmallM<4>(n, m, a, b, c);
  if (m < 16 && k == 32) return NNSmallM<2>(n, m, a, b, c);
  const int full = m / 16 * 16;
  if (full > 0) {
    // Full 16-column panels straight into C (row stride m), then the masked tail.
    for (int j0 = 0; j0 < full; j0 += 16) {
      int64_t s = 0;
      for (; s + 16 <= n; s += 16) NNBlock<16, 1>(k, m, a + s * k, b + j0, c + s * m + j0);
      for (; s < n; ++s) NNBlock<1, 1>(k, m, a + s * k, b + j0, c + s * m + j0);
    }
  }
  NNTail(n, k, m, full, a, b, c);
}

template <>
void GemmTNAcc<float>(int64_t n, int k, int m, const float* a, const float* b, float* c) {
  if (m % 64 == 0) return TNPanel<6, 4>(n, k, m, a, b, c);
  if (m % 32 == 0) return TNPanel<12, 2>(n, k, m, a, b, c);
  if (m % 16 == 0) return TNPanel<16, 1>(n, k, m, a, b, c);
  if (k == 64 && m == 3) return TNSmallM<3, 4>(n, a, b, c);
  if (k == 64 && m == 1) return TNSmallM<1, 4>(n, a, b, c);
  if (k == 32 && m == 3) return TNSmallM<3, 2>(n, a, b, c);
  GemmTNAccGeneric(n, k, m, a, b, c);
}

const char* GemmKernelName() { return "avx512"; }

#elif defined(__AVX2__) && defined(__FMA__)
namespace {

// The same register blocking with 8-wide vectors (AVX2 has 16 ymm registers: R * MV accumulators,
// MV columns of B and one broadcast of A must fit). Any row stride m: blocks of 8 columns, the
// last m % 8 columns by scalar loops.

// C[s, j0..j0+8*MV) = sum_p A[s, p] B[p, j] for R rows.
template <int R, int MV>
inline void NNBlock8(int k, int m, const float* a, const float* b, float* c) {
  __m256 acc[R][MV];
  for (int r = 0; r < R; ++r)
    for (int v = 0; v < MV; ++v) acc[r][v] = _mm256_setzero_ps();
  for (int p = 0; p < k; ++p) {
    __m256 bv[MV];
    for (int v = 0; v < MV; ++v) bv[v] = _mm256_loadu_ps(b + static_cast<int64_t>(p) * m + 8 * v);
    for (int r = 0; r < R; ++r) {
      const __m256 av = _mm256_broadcast_ss(a + static_cast<int64_t>(r) * k + p);
      for (int v = 0; v < MV; ++v) acc[r][v] = _mm256_fmadd_ps(av, bv[v], acc[r][v]);
    }
  }
  for (int r = 0; r < R; ++r)
    for (int v = 0; v < MV; ++v) _mm256_storeu_ps(c + static_cast<int64_t>(r) * m + 8 * v, acc[r][v]);
}

// Columns [j0, j1) (a multiple of 8 * MV wide) of every row.
template <int R, int MV>
void NNPanel8(int64_t n, int k, int m, int j0, int j1, const float* a, const float* b, float* c) {
  for (int j = j0; j < j1; j += 8 * MV) {
    int64_t s = 0;
    for (; s + R <= n; s += R) NNBlock8<R, MV>(k, m, a + s * k, b + j, c + s * m + j);
    for (; s < n; ++s) NNBlock8<1, MV>(k, m, a + s * k, b + j, c + s * m + j);
  }
}

// C[p, j0..j0+8*MV) += sum_s A[s, p] B[s, j] for R rows p.
template <int R, int MV>
inline void TNBlock8(int64_t n, int k, int m, const float* a, const float* b, float* c) {
  __m256 acc[R][MV];
  for (int r = 0; r < R; ++r)
    for (int v = 0; v < MV; ++v) acc[r][v] = _mm256_loadu_ps(c + static_cast<int64_t>(r) * m + 8 * v);
  for (int64_t s = 0; s < n; ++s) {
    __m256 bv[MV];
    for (int v = 0; v < MV; ++v) bv[v] = _mm256_loadu_ps(b + s * m + 8 * v);
    for (int r = 0; r < R; ++r) {
      const __m256 av = _mm256_broadcast_ss(a + s * k + r);
      for (int v = 0; v < MV; ++v) acc[r][v] = _mm256_fmadd_ps(av, bv[v], acc[r][v]);
    }
  }
  for (int r = 0; r < R; ++r)
    for (int v = 0; v < MV; ++v) _mm256_storeu_ps(c + static_cast<int64_t>(r) * m + 8 * v, acc[r][v]);
}

template <int R, int MV>
void TNPanel8(int64_t n, int k, int m, int j0, int j1, const float* a, const float* b, float* c) {
  for (int j = j0; j < j1; j += 8 * MV) {
    int p = 0;
    for (; p + R <= k; p += R) TNBlock8<R, MV>(n, k, m, a + p, b + j, c + static_cast<int64_t>(p) * m + j);
    for (; p < k; ++p) TNBlock8<1, MV>(n, k, m, a + p, b + j, c + static_cast<int64_t>(p) * m + j);
  }
}

float HorizontalSum(__m256 v) {
  const __m128 s = _mm_add_ps(_mm256_castps256_ps128(v), _mm256_extractf128_ps(v, 1));
  const __m128 t = _mm_add_ps(s, _mm_movehl_ps(s, s));
  return _mm_cvtss_f32(_mm_add_ss(t, _mm_shuffle_ps(t, t, 1)));
}

// C[n, m] = A[n, k] B[k, m] for m < 8 columns and k = 8 KV (the 3-wide output layers): vectorised
// along k, one dot product per (row, column) from the columns of B gathered once.
template <int KV>
void NNSmallM8(int64_t n, int m, const float* a, const float* b, float* c) {
  constexpr int k = 8 * KV;
  alignas(32) float bt[8][k];
  for (int j = 0; j < m; ++j)
    for (int p = 0; p < k; ++p) bt[j][p] = b[int64_t{p} * m + j];
  for (int64_t s = 0; s < n; ++s) {
    __m256 av[KV];
    for (int v = 0; v < KV; ++v) av[v] = _mm256_loadu_ps(a + s * k + 8 * v);
    for (int j = 0; j < m; ++j) {
      __m256 acc = _mm256_mul_ps(av[0], _mm256_load_ps(&bt[j][0]));
      for (int v = 1; v < KV; ++v) acc = _mm256_fmadd_ps(av[v], _mm256_load_ps(&bt[j][8 * v]), acc);
      c[s * m + j] = HorizontalSum(acc);
    }
  }
}

// C[k, m] += A[n, k]^T B[n, m] for m = M < 8 and k = 8 KV: C^T accumulated in registers.
template <int M, int KV>
void TNSmallM8(int64_t n, const float* a, const float* b, float* c) {
  constexpr int k = 8 * KV;
  __m256 acc[M][KV];
  for (int j = 0; j < M; ++j)
    for (int v = 0; v < KV; ++v) acc[j][v] = _mm256_setzero_ps();
  for (int64_t s = 0; s < n; ++s) {
    __m256 av[KV];
    for (int v = 0; v < KV; ++v) av[v] = _mm256_loadu_ps(a + s * k + 8 * v);
    for (int j = 0; j < M; ++j) {
      const __m256 bj = _mm256_broadcast_ss(b + s * M + j);
      for (int v = 0; v < KV; ++v) acc[j][v] = _mm256_fmadd_ps(bj, av[v], acc[j][v]);
    }
  }
  alignas(32) float tmp[M][k];
  for (int j = 0; j < M; ++j)
    for (int v = 0; v < KV; ++v) _mm256_store_ps(&tmp[j][8 * v], acc[j][v]);
  for (int p = 0; p < k; ++p)
    for (int j = 0; j < M; ++j) c[p * M + j] += tmp[j][p];
}

}  // namespace

template <>
void GemmNN<float>(int64_t n, int k, int m, const float* a, const float* b, float* c) {
  if (m < 8) {
    if (k == 64) return NNSmallM8<8>(n, m, a, b, c);
    if (k == 32) return NNSmallM8<4>(n, m, a, b, c);
    if (k == 16) return NNSmallM8<2>(n, m, a, b, c);
    return GemmNNGeneric(n, k, m, a, b, c);
  }
  const int wide = m / 16 * 16, full = m / 8 * 8;
  NNPanel8<6, 2>(n, k, m, 0, wide, a, b, c);
  NNPanel8<12, 1>(n, k, m, wide, full, a, b, c);
  // The last m % 8 columns.
  for (int64_t s = 0; s < n && full < m; ++s)
    for (int j = full; j < m; ++j) {
      float sum = 0;
      for (int p = 0; p < k; ++p) sum += a[s * k + p] * b[static_cast<int64_t>(p) * m + j];
      c[s * m + j] = sum;
    }
}

template <>
void GemmTNAcc<float>(int64_t n, int k, int m, const float* a, const float* b, float* c) {
  if (m < 8) {
    if (k == 64 && m == 3) return TNSmallM8<3, 8>(n, a, b, c);
    if (k == 64 && m == 1) return TNSmallM8<1, 8>(n, a, b, c);
    if (k == 32 && m == 3) return TNSmallM8<3, 4>(n, a, b, c);
    if (k == 32 && m == 1) return TNSmallM8<1, 4>(n, a, b, c);
    return GemmTNAccGeneric(n, k, m, a, b, c);
  }
  const int wide = m / 16 * 16, full = m / 8 * 8;
  TNPanel8<6, 2>(n, k, m, 0, wide, a, b, c);
  TNPanel8<12, 1>(n, k, m, wide, full, a, b, c);
  // The last m % 8 columns.
  if (full < m)
    for (int64_t s = 0; s < n; ++s)
      for (int p = 0; p < k; ++p) {
        const float av = a[s * k + p];
        for (int j = full; j < m; ++j) c[static_cast<int64_t>(p) * m + j] += av * b[s * m + j];
      }
}

const char* GemmKernelName() { return "avx2"; }

#else

template <>
void GemmNN<float>(int64_t n, int k, int m, const float* a, const float* b, float* c) {
  GemmNNGeneric(n, k, m, a, b, c);
}
template <>
void GemmTNAcc<float>(int64_t n, int k, int m, const float* a, const float* b, float* c) {
  GemmTNAccGeneric(n, k, m, a, b, c);
}
const char* GemmKernelName() { return "generic"; }

#endif

}  // namespace icef::nn
