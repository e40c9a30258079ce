#include "icef/nn/gemm.h"

#if defined(__AVX512F__)
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

}  // namespace

template <>
void GemmNN<float>(int64_t n, int k, int m, const float* a, const float* b, float* c) {
  if (m % 64 == 0) return NNPanel<6, 4>(n, k, m, a, b, c);
  if (m % 32 == 0) return NNPanel<12, 2>(n, k, m, a, b, c);
  if (m % 16 == 0) return NNPanel<16, 1>(n, k, m, a, b, c);
  GemmNNGeneric(n, k, m, a, b, c);
}

template <>
void GemmTNAcc<float>(int64_t n, int k, int m, const float* a, const float* b, float* c) {
  if (m % 64 == 0) return TNPanel<6, 4>(n, k, m, a, b, c);
  if (m % 32 == 0) return TNPanel<12, 2>(n, k, m, a, b, c);
  if (m % 16 == 0) return TNPanel<16, 1>(n, k, m, a, b, c);
  GemmTNAccGeneric(n, k, m, a, b, c);
}

const char* GemmKernelName() { return "avx512"; }

#else

template <>
void GemmNN<float>(int64_t n, int k, int m, const float* a, const float* b, float* c) {
  GemmNNGeneric(n, k, m, a, b, c);
}
template <>
void GemmTNAcc<float>(int64_t n, int k, int m, const float* a, const float* b, float* c) {
  GemmTNAccGeneric(n, k, m, a, b, c);
}
#if defined(__AVX2__)
const char* GemmKernelName() { return "avx2 (auto-vectorised)"; }
#else
const char* GemmKernelName() { return "generic"; }
#endif

#endif

}  // namespace icef::nn
