#include "icef/nn/gemm_bf16.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <vector>

#include "icef/core/rng.h"
#include "icef/nn/mlp.h"

namespace icef::nn {
namespace {

std::vector<float> Random(int64_t size, uint64_t seed) {
  Rng rng(seed, StreamId("gemm_bf16_test"));
  std::vector<float> v(size);
  for (float& x : v) x = static_cast<float>(rng.Uniform(-1.0, 1.0));
  return v;
}

TEST(Bf16Test, RoundsToNearestEven) {
  EXPECT_EQ(FloatToBf16(1.f), 0x3f80);
  EXPECT_EQ(FloatToBf16(-2.f), 0xc000);
  EXPECT_EQ(FloatToBf16(0.f), 0x0000);
  // 1 + 2^-8 lies halfway between 1 and 1 + 2^-7: ties go to the even mantissa (1).
  EXPECT_EQ(FloatToBf16(1.f + std::ldexp(1.f, -8)), 0x3f80);
  // 1 + 3 * 2^-8 lies halfway between 1 + 2^-7 and 1 + 2^-6: ties go to 1 + 2^-6 (even).
  EXPECT_EQ(FloatToBf16(1.f + 3.f * std::ldexp(1.f, -8)), 0x3f82);
  EXPECT_EQ(FloatToBf16(1.f + 1.5f * std::ldexp(1.f, -8)), 0x3f81);  // above the tie: up
  EXPECT_TRUE(std::isnan(Bf16ToFloat(FloatToBf16(std::numeric_limits<float>::quiet_NaN()))));
  EXPECT_TRUE(std::isinf(Bf16ToFloat(FloatToBf16(std::numeric_limits<float>::infinity()))));
  for (float x : Random(1000, 1))
    EXPECT_NEAR(Bf16ToFloat(FloatToBf16(x)), x, std::abs(x) * std::ldexp(1.f, -8));
}

TEST(Bf16Test, PacksPairsOfRowsPerColumn) {
  const int k = 5, m = 16;
  const std::vector<float> b = Random(k * m, 2);
  std::vector<uint16_t> packed(Bf16PackedSize(k, m), 0xffff);
  ASSERT_EQ(packed.size(), size_t{3 * 2 * 16});
  PackBf16Pairs(k, m, b.data(), packed.data());
  for (int p = 0; p < 6; ++p)
    for (int j = 0; j < m; ++j) {
      const uint16_t expected = p < k ? FloatToBf16(b[p * m + j]) : uint16_t{0};
      EXPECT_EQ(packed[(p / 2) * 2 * m + 2 * j + p % 2], expected) << p << " " << j;
    }
}

// The kernel's result is the FP32 sum of the products of the BF16-rounded operands: compare with
// that sum in double (the only difference left is FP32 rounding in the accumulation).
TEST(Bf16Test, GemmEqualsTheProductOfRoundedOperands) {
  if (!Bf16Supported()) GTEST_SKIP() << "this build has no AVX512-BF16 kernel";
  for (int m : {16, 32, 48, 64, 128})
    for (int k : {1, 11, 20, 32, 50, 64, 65})
      for (int64_t n : {1, 7, 100, 203}) {
        const std::vector<float> a = Random(n * k, 3 + k), b = Random(int64_t{k} * m, 4 + m);
        std::vector<uint16_t> packed(Bf16PackedSize(k, m));
        PackBf16Pairs(k, m, b.data(), packed.data());
        std::vector<float> c(n * m, -7.f);
        GemmNNBf16(n, k, m, a.data(), packed.data(), c.data());
        for (int64_t s = 0; s < n; ++s)
          for (int j = 0; j < m; ++j) {
            double ref = 0, mag = 0;
            for (int p = 0; p < k; ++p) {
              const double prod = double(Bf16ToFloat(FloatToBf16(a[s * k + p]))) *
                                  double(Bf16ToFloat(FloatToBf16(b[int64_t{p} * m + j])));
              ref += prod;
              mag += std::abs(prod);
            }
            ASSERT_NEAR(c[s * m + j], ref, 1e-6 * (1 + mag)) << "m " << m << " k " << k << " n " << n;
          }
      }
}

// The weight-gradient kernel adds the FP32 sum of the products of the BF16-rounded operands to C
// (odd sample counts and more than one 256-sample pass included).
TEST(Bf16Test, GemmTNAccAddsTheProductOfRoundedOperands) {
  if (!Bf16Supported()) GTEST_SKIP() << "this build has no AVX512-BF16 kernel";
  for (int m : {16, 32, 64, 128})
    for (int k : {3, 16, 55, 64})
      for (int64_t n : {1, 7, 128, 301}) {
        const std::vector<float> a = Random(n * k, 7 + k), b = Random(n * m, 8 + m);
        const std::vector<float> c0 = Random(int64_t{k} * m, 9);
        std::vector<float> c = c0;
        GemmTNAccBf16(n, k, m, a.data(), b.data(), c.data());
        for (int p = 0; p < k; ++p)
          for (int j = 0; j < m; ++j) {
            double ref = c0[int64_t{p} * m + j], mag = std::abs(ref);
            for (int64_t s = 0; s < n; ++s) {
              const double prod = double(Bf16ToFloat(FloatToBf16(a[s * k + p]))) *
                                  double(Bf16ToFloat(FloatToBf16(b[s * m + j])));
              ref += prod;
              mag += std::abs(prod);
            }
            ASSERT_NEAR(c[int64_t{p} * m + j], ref, 1e-6 * (1 + mag))
                << "m " << m << " k " << k << " n " << n;
          }
      }
}

// An Mlp with bf16_inference: inference passes stay within BF16's precision of the FP32 ones,
// training passes (keep_for_backward) are exactly FP32.
TEST(Bf16Test, MlpInferenceIsCloseToFp32AndTrainingIsUnchanged) {
  ParameterStore store;
  MlpOptions o;
  o.widths = {50, 64, 64, 64, 3};
  Mlp fp32(o, &store, "fp32");
  o.bf16_inference = true;
  Mlp bf16(o, &store, "bf16");
  fp32.Initialize(5);
  std::memcpy(bf16.weights(), fp32.weights(), fp32.num_params() * sizeof(float));
  ASSERT_EQ(0, std::memcmp(fp32.weights(), bf16.weights(), fp32.num_params() * sizeof(float)));
  const int64_t n = 500;
  const std::vector<float> x = Random(n * 50, 6);
  std::vector<float> y32(n * 3), y16(n * 3), train16(n * 3);
  MlpContext c32, c16;
  const Executor ex(2);
  fp32.Forward(ex, n, x.data(), y32.data(), &c32, false);
  bf16.Forward(ex, n, x.data(), y16.data(), &c16, false);
  double err = 0, scale = 0;
  for (int64_t i = 0; i < n * 3; ++i)
    err = std::max(err, double(std::abs(y16[i] - y32[i]))), scale = std::max(scale, double(std::abs(y32[i])));
  EXPECT_LT(err, 0.02 * scale);
  if (Bf16Supported()) {
    EXPECT_GT(err, 0.0);  // the BF16 path really ran
  }
  bf16.Forward(ex, n, x.data(), train16.data(), &c16, true);
  EXPECT_EQ(0, std::memcmp(train16.data(), y32.data(), y32.size() * sizeof(float)));
}

// MlpBackward with the BF16 products, on the same forward pass as FP32: the input and weight
// gradients stay within BF16's precision (8 significant bits per operand, FP32 sums).
TEST(Bf16Test, MlpBackwardProductsStayWithinBf16Precision) {
  if (!Bf16Supported()) GTEST_SKIP() << "this build has no AVX512-BF16 kernel";
  const MlpShape s({32, 64, 64, 16}, Activation::kNone);
  const int64_t n = 128;
  std::vector<float> w = Random(s.num_params(), 13);
  for (float& v : w) v *= 0.3f;
  const std::vector<float> x = Random(n * 32, 14), dy = Random(n * 16, 15);
  std::vector<float> hidden(n * s.hidden_per_sample()), y(n * 16), wt(s.num_params());
  MlpForward<float>(s, w.data(), n, x.data(), hidden.data(), y.data());
  MlpTransposeWeights<float>(s, w.data(), wt.data());
  MlpBf16Weights packed;
  packed.PackTransposed(s, wt.data());
  std::vector<float> dw32(s.num_params()), dw16(s.num_params()), dx32(n * 32), dx16(n * 32),
      scratch(MlpBackwardScratch(s, n));
  MlpBackward<float>(s, wt.data(), n, x.data(), hidden.data(), y.data(), dy.data(), dw32.data(), dx32.data(),
                     scratch.data());
  MlpBackward<float>(s, wt.data(), n, x.data(), hidden.data(), y.data(), dy.data(), dw16.data(), dx16.data(),
                     scratch.data(), &packed);
  auto max_rel = [](const float* got, const float* ref, int64_t size) {
    double err = 0, scale = 0;
    for (int64_t i = 0; i < size; ++i) {
      err = std::max(err, double(std::abs(got[i] - ref[i])));
      scale = std::max(scale, double(std::abs(ref[i])));
    }
    return err / scale;
  };
  EXPECT_LT(max_rel(dx16.data(), dx32.data(), n * 32), 0.01);
  for (int l = 0; l < s.num_layers(); ++l) {
    const int64_t off = s.WeightOffset(l), size = s.WeightOffset(l + 1) - off;
    EXPECT_LT(max_rel(dw16.data() + off, dw32.data() + off, size), 0.01) << "layer " << l;
    if (Bf16Supported()) {
      EXPECT_GT(max_rel(dw16.data() + off, dw32.data() + off, size), 0.0) << "layer " << l;
    }
  }
}

// An Mlp with bf16_training: its training passes stay close to FP32 and do not depend on the
// thread count. The forward pass differs from FP32 by about 0.4 %, enough to switch a ReLU whose
// pre-activation is that close to zero, which changes that sample's gradient outright (a few
// percent of the samples here): hence RMS bounds over the batch, several times what the products
// alone give (MlpBackwardProductsStayWithinBf16Precision) but far below what a wrong product
// would (of the order of 1).
TEST(Bf16Test, MlpTrainingPassesAreCloseToFp32AndThreadIndependent) {
  const int64_t n = 700;
  const std::vector<int> widths = {32, 64, 64, 16};
  const std::vector<float> x = Random(n * widths[0], 10), dy = Random(n * widths.back(), 11);
  struct Pass {
    std::vector<float> y, dx, dw;
  };
  auto run = [&](bool bf16, int threads) {
    ParameterStore store;
    MlpOptions o;
    o.widths = widths;
    o.bf16_training = bf16;
    Mlp mlp(o, &store, "mlp");
    mlp.Initialize(12);
    Pass p{std::vector<float>(n * widths.back()), std::vector<float>(n * widths[0]), {}};
    MlpContext ctx;
    const Executor ex(threads);
    mlp.Forward(ex, n, x.data(), p.y.data(), &ctx, true);
    store.ZeroGrads();
    mlp.Backward(ex, n, x.data(), p.y.data(), dy.data(), &ctx, p.dx.data());
    p.dw.assign(mlp.weight_grads(), mlp.weight_grads() + mlp.num_params());
    return p;
  };
  const Pass fp32 = run(false, 2), bf16 = run(true, 2), bf16_one = run(true, 1);
  auto rms_rel = [](const std::vector<float>& got, const std::vector<float>& ref) {
    double err = 0, norm = 0;
    for (size_t i = 0; i < ref.size(); ++i) {
      err += double(got[i] - ref[i]) * double(got[i] - ref[i]);
      norm += double(ref[i]) * double(ref[i]);
    }
    return std::sqrt(err / norm);
  };
  EXPECT_LT(rms_rel(bf16.y, fp32.y), 0.01);
  EXPECT_LT(rms_rel(bf16.dx, fp32.dx), 0.1);
  EXPECT_LT(rms_rel(bf16.dw, fp32.dw), 0.08);
  if (Bf16Supported()) {
    EXPECT_GT(rms_rel(bf16.y, fp32.y), 0.0);  // the BF16 path really ran
  }
  EXPECT_EQ(bf16.y, bf16_one.y);
  EXPECT_EQ(bf16.dx, bf16_one.dx);
  EXPECT_EQ(bf16.dw, bf16_one.dw);
}

}  // namespace
}  // namespace icef::nn
