// Products in BF16 with FP32 accumulation (AVX512-BF16's vdpbf16ps: 32 products per instruction
// where the FP32 kernel does 16), for the layers of an Mlp in inference (renders, evaluation,
// occupancy updates) and, with MlpOptions::bf16_training, in training:
//   C[n, m] = bf16(A)[n, k] · bf16(B)[k, m]   accumulated in FP32.
// Both operands are rounded to BF16 (8 significant bits, round to nearest even); the products and
// sums are FP32. B, a layer's Wt, is packed once per batch into pairs of consecutive k rows,
// interleaved per column: packed[(p / 2) * 2m + 2j + (p % 2)] = bf16(B[p, j]), a zero row padding
// odd k. Builds without AVX512-BF16 (and columns that are not a multiple of 16) use the FP32 kernel
// on the unpacked weights instead; Bf16Supported() says which.
#pragma once

#include <cstdint>
#include <vector>

namespace icef::nn {

// True when this build has the AVX512-BF16 kernel.
bool Bf16Supported();

// Round to nearest even, as the hardware conversion does (NaN stays NaN).
uint16_t FloatToBf16(float f);
float Bf16ToFloat(uint16_t h);

// uint16 values PackBf16Pairs writes for a [k, m] matrix.
inline int64_t Bf16PackedSize(int k, int m) { return int64_t{(k + 1) / 2} * 2 * m; }
void PackBf16Pairs(int k, int m, const float* b, uint16_t* packed);

// C[n, m] = A[n, k] · B[k, m] from B packed by PackBf16Pairs; m must be a multiple of 16 and the
// build must have the kernel (Bf16Supported()).
void GemmNNBf16(int64_t n, int k, int m, const float* a, const uint16_t* packed, float* c);

// The weight gradient in BF16: C[k, m] += bf16(A)[n, k]^T · bf16(B)[n, m], FP32 sums (per pass
// of 256 samples, then added to C). Both operands are packed internally into pairs of samples;
// m must be a multiple of 16 and the build must have the kernel.
void GemmTNAccBf16(int64_t n, int k, int m, const float* a, const float* b, float* c);

}  // namespace icef::nn
