#include "icef/nn/gemm_bf16.h"

#include <algorithm>
#include <cstring>

#include "icef/core/status.h"

#if defined(__AVX512BF16__) && defined(__AVX512BW__)
#include <immintrin.h>
#define ICEF_HAVE_BF16_KERNEL 1
#endif

namespace icef::nn {

bool Bf16Supported() {
#ifdef ICEF_HAVE_BF16_KERNEL
  return true;
#else
  return false;
#endif
}

uint16_t FloatToBf16(float f) {
  uint32_t u;
  std::memcpy(&u, &f, 4);
  if ((u & 0x7fffffffu) > 0x7f800000u) return static_cast<uint16_t>((u >> 16) | 0x40u);  // quiet NaN
  u += 0x7fffu + ((u >> 16) & 1u);
  return static_cast<uint16_t>(u >> 16);
}

float Bf16ToFloat(uint16_t h) {
  const uint32_t u = uint32_t{h} << 16;
  float f;
  std::memcpy(&f, &u, 4);
  return f;
}

#ifdef ICEF_HAVE_BF16_KERNEL
namespace {
// Rows p and p + 1 (when p + 1 < k) of b [k, m], 16 columns from j0, converted and interleaved
// into out: out[2j] = b[p, j0 + j], out[2j + 1] = b[p + 1, j0 + j].
inline void PackPairVector(int k, int m, int p, int j0, const float* b, uint16_t* out) {
  const int left = m - j0;
  const __mmask16 mask = left >= 16 ? __mmask16(0xffff) : __mmask16((1u << left) - 1u);
  const __m512 lo = _mm512_maskz_loadu_ps(mask, b + int64_t{p} * m + j0);
  const __m512 hi =
      p + 1 < k ? _mm512_maskz_loadu_ps(mask, b + int64_t{p + 1} * m + j0) : _mm512_setzero_ps();
  // [lo_0 .. lo_15, hi_0 .. hi_15] -> lo_0, hi_0, lo_1, hi_1, ...
  const __m512i both = (__m512i)_mm512_cvtne2ps_pbh(hi, lo);
  const __m512i order = _mm512_set_epi16(31, 15, 30, 14, 29, 13, 28, 12, 27, 11, 26, 10, 25, 9, 24, 8, 23, 7,
                                         22, 6, 21, 5, 20, 4, 19, 3, 18, 2, 17, 1, 16, 0);
  const __mmask32 store = left >= 16 ? __mmask32(0xffffffffu) : __mmask32((1u << (2 * left)) - 1u);
  _mm512_mask_storeu_epi16(out, store, _mm512_permutexvar_epi16(order, both));
}
}  // namespace
#endif

void PackBf16Pairs(int k, int m, const float* b, uint16_t* packed) {
#ifdef ICEF_HAVE_BF16_KERNEL
  for (int p = 0; p < k; p += 2)
    for (int j0 = 0; j0 < m; j0 += 16)
      PackPairVector(k, m, p, j0, b, packed + int64_t{p / 2} * 2 * m + 2 * j0);
#else
  for (int p = 0; p < k; p += 2)
    for (int j = 0; j < m; ++j) {
      uint16_t* out = packed + int64_t{p / 2} * 2 * m + 2 * j;
      out[0] = FloatToBf16(b[int64_t{p} * m + j]);
      out[1] = p + 1 < k ? FloatToBf16(b[int64_t{p + 1} * m + j]) : uint16_t{0};
    }
#endif
}

#ifdef ICEF_HAVE_BF16_KERNEL
namespace {

// R rows of C, MV vectors of 16 columns; a_bf: R rows of kp (even) BF16 values, zero-padded.
template <int R, int MV>
inline void Bf16Block(int kp, int m, const uint16_t* a_bf, const uint16_t* packed, float* c) {
  __m512 acc[R][MV];
  for (int r = 0; r < R; ++r)
    for (int v = 0; v < MV; ++v) acc[r][v] = _mm512_setzero_ps();
  for (int p = 0; p < kp; p += 2) {
    __m512bh bv[MV];
    const uint16_t* row = packed + int64_t{p / 2} * 2 * m;
    for (int v = 0; v < MV; ++v) bv[v] = (__m512bh)_mm512_loadu_si512(row + 32 * v);
    for (int r = 0; r < R; ++r) {
      uint32_t pair;
      std::memcpy(&pair, a_bf + int64_t{r} * kp + p, 4);
      const __m512bh av = (__m512bh)_mm512_set1_epi32(static_cast<int>(pair));
      for (int v = 0; v < MV; ++v) acc[r][v] = _mm512_dpbf16_ps(acc[r][v], av, bv[v]);
    }
  }
  for (int r = 0; r < R; ++r)
    for (int v = 0; v < MV; ++v) _mm512_storeu_ps(c + int64_t{r} * m + 16 * v, acc[r][v]);
}

// Rows of A to BF16, each padded with zeros to kp values.
void ConvertRows(int64_t rows, int k, int kp, const float* a, uint16_t* out) {
  for (int64_t s = 0; s < rows; ++s) {
    const float* src = a + s * k;
    uint16_t* dst = out + s * kp;
    for (int p = 0; p < kp; p += 32) {
      // Masked loads read zeros past k; the masked store writes up to kp.
      const int left = k - p;
      const __mmask16 lo = left >= 16 ? __mmask16(0xffff)
                           : left > 0 ? __mmask16((1u << left) - 1u)
                                      : __mmask16(0);
      const __mmask16 hi = left >= 32  ? __mmask16(0xffff)
                           : left > 16 ? __mmask16((1u << (left - 16)) - 1u)
                                       : __mmask16(0);
      const __m512bh v =
          _mm512_cvtne2ps_pbh(_mm512_maskz_loadu_ps(hi, src + p + 16), _mm512_maskz_loadu_ps(lo, src + p));
      const int out = std::min(32, kp - p);
      _mm512_mask_storeu_epi16(dst + p, out >= 32 ? __mmask32(0xffffffffu) : __mmask32((1u << out) - 1u),
                               (__m512i)v);
    }
  }
}

template <int R, int MV>
void Bf16Panel(int64_t n, int k, int m, const float* a, const uint16_t* packed, float* c) {
  const int kp = (k + 1) & ~1;
  constexpr int64_t kRowsPerPass = 96;  // a multiple of R (6, 12, 16 -> 96 is one of each)
  thread_local std::vector<uint16_t> a_bf;
  if (a_bf.size() < size_t(kRowsPerPass * kp)) a_bf.resize(size_t(kRowsPerPass * kp));
  for (int64_t s0 = 0; s0 < n; s0 += kRowsPerPass) {
    const int64_t rows = std::min<int64_t>(kRowsPerPass, n - s0);
    ConvertRows(rows, k, kp, a + s0 * k, a_bf.data());
    for (int j0 = 0; j0 < m; j0 += 16 * MV) {
      int64_t s = 0;
      for (; s + R <= rows; s += R)
        Bf16Block<R, MV>(kp, m, a_bf.data() + s * kp, packed + 2 * j0, c + (s0 + s) * m + j0);
      for (; s < rows; ++s)
        Bf16Block<1, MV>(kp, m, a_bf.data() + s * kp, packed + 2 * j0, c + (s0 + s) * m + j0);
    }
  }
}

// C[i0 .. i0+R, j0 .. j0+16MV] += the products of `pairs` sample pairs: a_pk and b_pk are A [n, k]
// and B [n, m] packed by PackBf16Pairs, offset to feature i0 and column j0.
template <int R, int MV>
inline void Bf16TNBlock(int64_t pairs, int k, int m, const uint16_t* a_pk, const uint16_t* b_pk, float* c) {
  __m512 acc[R][MV];
  for (int r = 0; r < R; ++r)
    for (int v = 0; v < MV; ++v) acc[r][v] = _mm512_setzero_ps();
  for (int64_t q = 0; q < pairs; ++q) {
    __m512bh bv[MV];
    const uint16_t* brow = b_pk + q * 2 * m;
    for (int v = 0; v < MV; ++v) bv[v] = (__m512bh)_mm512_loadu_si512(brow + 32 * v);
    const uint16_t* arow = a_pk + q * 2 * k;
    for (int r = 0; r < R; ++r) {
      uint32_t pair;
      std::memcpy(&pair, arow + 2 * r, 4);
      const __m512bh av = (__m512bh)_mm512_set1_epi32(static_cast<int>(pair));
      for (int v = 0; v < MV; ++v) acc[r][v] = _mm512_dpbf16_ps(acc[r][v], av, bv[v]);
    }
  }
  for (int r = 0; r < R; ++r)
    for (int v = 0; v < MV; ++v) {
      float* out = c + int64_t{r} * m + 16 * v;
      _mm512_storeu_ps(out, _mm512_add_ps(_mm512_loadu_ps(out), acc[r][v]));
    }
}

template <int R, int MV>
void Bf16TNPanel(int64_t n, int k, int m, const float* a, const float* b, float* c) {
  constexpr int64_t kSamplesPerPass = 256;
  thread_local std::vector<uint16_t> a_pk, b_pk;
  if (a_pk.size() < size_t(Bf16PackedSize(kSamplesPerPass, k)))
    a_pk.resize(size_t(Bf16PackedSize(kSamplesPerPass, k)));
  if (b_pk.size() < size_t(Bf16PackedSize(kSamplesPerPass, m)))
    b_pk.resize(size_t(Bf16PackedSize(kSamplesPerPass, m)));
  for (int64_t s0 = 0; s0 < n; s0 += kSamplesPerPass) {
    const int rows = static_cast<int>(std::min(kSamplesPerPass, n - s0));
    const int64_t pairs = (rows + 1) / 2;
    PackBf16Pairs(rows, k, a + s0 * k, a_pk.data());
    PackBf16Pairs(rows, m, b + s0 * m, b_pk.data());
    for (int j0 = 0; j0 < m; j0 += 16 * MV) {
      int i = 0;
      for (; i + R <= k; i += R)
        Bf16TNBlock<R, MV>(pairs, k, m, a_pk.data() + 2 * i, b_pk.data() + 2 * j0, c + int64_t{i} * m + j0);
      for (; i < k; ++i)
        Bf16TNBlock<1, MV>(pairs, k, m, a_pk.data() + 2 * i, b_pk.data() + 2 * j0, c + int64_t{i} * m + j0);
    }
  }
}

}  // namespace
#endif

void GemmNNBf16(int64_t n, int k, int m, const float* a, const uint16_t* packed, float* c) {
  ICEF_CHECK(m % 16 == 0, "GemmNNBf16: m must be a multiple of 16");
#ifdef ICEF_HAVE_BF16_KERNEL
  if (m % 64 == 0) return Bf16Panel<6, 4>(n, k, m, a, packed, c);
  if (m % 32 == 0) return Bf16Panel<12, 2>(n, k, m, a, packed, c);
  return Bf16Panel<16, 1>(n, k, m, a, packed, c);
#else
  (void)n, (void)k, (void)a, (void)packed, (void)c;
  ICEF_CHECK(false, "GemmNNBf16: this build has no AVX512-BF16 kernel");
#endif
}

void GemmTNAccBf16(int64_t n, int k, int m, const float* a, const float* b, float* c) {
  ICEF_CHECK(m % 16 == 0, "GemmTNAccBf16: m must be a multiple of 16");
#ifdef ICEF_HAVE_BF16_KERNEL
  if (m % 64 == 0) return Bf16TNPanel<6, 4>(n, k, m, a, b, c);
  if (m % 32 == 0) return Bf16TNPanel<12, 2>(n, k, m, a, b, c);
  return Bf16TNPanel<16, 1>(n, k, m, a, b, c);
#else
  (void)n, (void)k, (void)a, (void)b, (void)c;
  ICEF_CHECK(false, "GemmTNAccBf16: this build has no AVX512-BF16 kernel");
#endif
}

}  // namespace icef::nn
