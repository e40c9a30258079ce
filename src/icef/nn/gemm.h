// The two dense products every layer needs, on row-major buffers with packed strides:
//   GemmNN:    C[n, m]  = A[n, k] · B[k, m]            (forward: X · Wt; backward data: dY · W)
//   GemmTNAcc: C[k, m] += A[n, k]^T · B[n, m]          (weight gradient: X^T · dY)
// Generic templates serve any scalar (double for gradient checks). The float versions use a
// register-blocked micro-kernel: AVX-512 (16-wide) when the build targets it (-march=native on an
// AVX-512 host, see docs/engine.md), else AVX2 + FMA (8-wide), else the generic loops.
#pragma once

#include <cstdint>

namespace icef::nn {

template <typename T>
void GemmNNGeneric(int64_t n, int k, int m, const T* a, const T* b, T* c) {
  for (int64_t s = 0; s < n; ++s) {
    T* cr = c + s * m;
    for (int j = 0; j < m; ++j) cr[j] = T(0);
    const T* ar = a + s * k;
    for (int p = 0; p < k; ++p) {
      const T av = ar[p];
      const T* br = b + static_cast<int64_t>(p) * m;
      for (int j = 0; j < m; ++j) cr[j] += av * br[j];
    }
  }
}

template <typename T>
void GemmTNAccGeneric(int64_t n, int k, int m, const T* a, const T* b, T* c) {
  for (int64_t s = 0; s < n; ++s) {
    const T* ar = a + s * k;
    const T* br = b + s * m;
    for (int p = 0; p < k; ++p) {
      const T av = ar[p];
      T* cr = c + static_cast<int64_t>(p) * m;
      for (int j = 0; j < m; ++j) cr[j] += av * br[j];
    }
  }
}

template <typename T>
inline void GemmNN(int64_t n, int k, int m, const T* a, const T* b, T* c) {
  GemmNNGeneric(n, k, m, a, b, c);
}
template <typename T>
inline void GemmTNAcc(int64_t n, int k, int m, const T* a, const T* b, T* c) {
  GemmTNAccGeneric(n, k, m, a, b, c);
}

template <>
void GemmNN<float>(int64_t n, int k, int m, const float* a, const float* b, float* c);
template <>
void GemmTNAcc<float>(int64_t n, int k, int m, const float* a, const float* b, float* c);

// "avx512", "avx2" or "generic": the float path compiled into this build.
const char* GemmKernelName();

}  // namespace icef::nn
