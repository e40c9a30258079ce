#include "icef/eval/lpips.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "icef/infer/cnn_test_util.h"
#include "icef/io/atomic_file.h"

namespace icef::eval {
namespace {

using namespace ::icef::infer::testing;
namespace fs = std::filesystem;

// Tiny AlexNet-shaped weights (the real kernel sizes, few channels); non-negative heads as LPIPS's.
LpipsWeights TinyWeights(uint64_t item) {
  const int kernels[5] = {11, 5, 3, 3, 3}, widths[5] = {4, 6, 5, 4, 3};
  LpipsWeights w;
  int cin = 3;
  Rng rng(5, StreamId("lpips_test_lin"), 0, item);
  for (int i = 0; i < 5; ++i) {
    w.conv[i] = RandomConv(kernels[i], kernels[i], cin, widths[i], true, item * 10 + i);
    for (float& v : w.conv[i].filters) v *= 0.5f;
    for (int c = 0; c < widths[i]; ++c) w.lin[i].push_back(float(rng.Uniform(0.0, 1.0)));
    cin = widths[i];
  }
  return w;
}

Image RandomImage(int w, int h, uint64_t item) {
  Rng rng(5, StreamId("lpips_test_image"), 0, item);
  Image image(w, h, 3);
  for (float& v : image.pixels) v = rng.Uniform();
  return image;
}

// Direct double-precision LPIPS from the definition.
double NaiveLpips(const LpipsWeights& w, const Image& a, const Image& b) {
  const double shift[3] = {-0.030, -0.088, -0.188}, scale[3] = {0.458, 0.448, 0.450};
  const int stride[5] = {4, 1, 1, 1, 1}, pad[5] = {2, 2, 1, 1, 1};
  auto taps = [&](const Image& im) {
    infer::Tensor3 x(im.height, im.width, 3);
    for (int y = 0; y < im.height; ++y)
      for (int i = 0; i < im.width; ++i)
        for (int c = 0; c < 3; ++c) x.At(y, i, c) = float((2.0 * im.At(i, y, c) - 1.0 - shift[c]) / scale[c]);
    std::vector<infer::Tensor3> out;
    for (int l = 0; l < 5; ++l) {
      if (l == 1 || l == 2) {
        infer::Tensor3 p((x.h - 3) / 2 + 1, (x.w - 3) / 2 + 1, x.c);
        for (int y = 0; y < p.h; ++y)
          for (int i = 0; i < p.w; ++i)
            for (int c = 0; c < x.c; ++c) {
              float m = -1e30f;
              for (int dy = 0; dy < 3; ++dy)
                for (int dx = 0; dx < 3; ++dx) m = std::max(m, x.At(2 * y + dy, 2 * i + dx, c));
              p.At(y, i, c) = m;
            }
        x = p;
      }
      x = NaiveConv(x, w.conv[l], stride[l], infer::Padding::Uniform(pad[l]));
      for (float& v : x.data) v = std::max(v, 0.f);
      out.push_back(x);
    }
    return out;
  };
  const auto ta = taps(a), tb = taps(b);
  double total = 0.0;
  for (int l = 0; l < 5; ++l) {
    double sum = 0.0;
    for (int y = 0; y < ta[l].h; ++y)
      for (int i = 0; i < ta[l].w; ++i) {
        double na = 0.0, nb = 0.0;
        for (int c = 0; c < ta[l].c; ++c) {
          na += std::pow(ta[l].At(y, i, c), 2);
          nb += std::pow(tb[l].At(y, i, c), 2);
        }
        for (int c = 0; c < ta[l].c; ++c) {
          const double d =
              ta[l].At(y, i, c) / (std::sqrt(na) + 1e-10) - tb[l].At(y, i, c) / (std::sqrt(nb) + 1e-10);
          sum += w.lin[l][c] * d * d;
        }
      }
    total += sum / (ta[l].h * ta[l].w);
  }
  return total;
}

TEST(LpipsTest, MatchesNaiveReferenceAndKnownProperties) {
  const LpipsWeights weights = TinyWeights(1);
  const Result<LpipsNet> net = LpipsNet::FromWeights(weights, "tiny");
  ASSERT_TRUE(net.ok()) << net.status().message();
  const Image a = RandomImage(64, 48, 1), b = RandomImage(64, 48, 2);
  const auto taps = net->Features(a);
  EXPECT_EQ(taps[0].h, 11);  // (48 + 4 - 11) / 4 + 1, floor
  EXPECT_EQ(taps[0].w, 15);  // (64 + 4 - 11) / 4 + 1
  EXPECT_EQ(taps[1].h, 5);   // max-pool 3/2
  EXPECT_EQ(taps[2].w, 3);
  EXPECT_EQ(taps[4].c, 3);
  const double ab = *net->Distance(a, b);
  EXPECT_NEAR(ab, NaiveLpips(weights, a, b), 1e-5 * std::max(1.0, ab));
  EXPECT_GT(ab, 0.0);
  EXPECT_NEAR(*net->Distance(b, a), ab, 1e-12);
  EXPECT_EQ(*net->Distance(a, a), 0.0);
  // A slightly perturbed image is closer than an unrelated one.
  Image a2 = a;
  for (float& v : a2.pixels) v = std::clamp(v + 0.02f, 0.f, 1.f);
  EXPECT_LT(*net->Distance(a, a2), ab);
}

TEST(LpipsTest, WeightsFileRoundTrip) {
  const fs::path path = fs::path(::testing::TempDir()) / "icef_lpips_tiny.bin";
  const LpipsWeights weights = TinyWeights(2);
  ASSERT_TRUE(WriteLpipsWeights(path, weights).ok());
  const Result<LpipsWeights> read = ReadLpipsWeights(path);
  ASSERT_TRUE(read.ok()) << read.status().message();
  for (int i = 0; i < 5; ++i) {
    EXPECT_EQ(read->conv[i].filters, weights.conv[i].filters) << i;  // OIHW on disk, HWIO in memory
    EXPECT_EQ(read->conv[i].bias, weights.conv[i].bias);
    EXPECT_EQ(read->lin[i], weights.lin[i]);
    EXPECT_EQ(read->conv[i].kh, weights.conv[i].kh);
  }
  const Result<std::optional<LpipsNet>> loaded = LoadLpipsIfConfigured(path.string());
  ASSERT_TRUE(loaded.ok() && loaded->has_value());
  const Image a = RandomImage(40, 40, 3), b = RandomImage(40, 40, 4);
  EXPECT_EQ(*(*loaded)->Distance(a, b), *LpipsNet::FromWeights(weights, "x")->Distance(a, b));
}

TEST(LpipsTest, UnavailableWithoutWeightsAndLoaderErrors) {
  const Result<std::optional<LpipsNet>> none = LoadLpipsIfConfigured("");
  ASSERT_TRUE(none.ok());
  EXPECT_FALSE(none->has_value());

  const fs::path dir = fs::path(::testing::TempDir());
  EXPECT_FALSE(LoadLpipsIfConfigured((dir / "icef_no_such_lpips.bin").string()).ok());
  ASSERT_TRUE(WriteFileAtomic(dir / "icef_lpips_bad.bin", "NOTLPIPS....").ok());
  const auto bad = ReadLpipsWeights(dir / "icef_lpips_bad.bin");
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.status().message().find("magic"), std::string::npos);

  // Truncated file.
  const fs::path good = dir / "icef_lpips_trunc.bin";
  ASSERT_TRUE(WriteLpipsWeights(good, TinyWeights(3)).ok());
  std::string bytes = *ReadFile(good);
  bytes.resize(bytes.size() - 7);
  ASSERT_TRUE(WriteFileAtomic(good, bytes).ok());
  const auto trunc = ReadLpipsWeights(good);
  ASSERT_FALSE(trunc.ok());
  EXPECT_NE(trunc.status().message().find("truncated"), std::string::npos) << trunc.status().message();

  // Channel chain broken / wrong kernel size.
  LpipsWeights broken = TinyWeights(4);
  broken.lin[2].pop_back();
  EXPECT_NE(ValidateLpipsWeights(broken, "w").message().find("lin2.weight"), std::string::npos);
  LpipsWeights kernel = TinyWeights(5);
  kernel.conv[0] = RandomConv(7, 7, 3, 4, true, 9);
  EXPECT_NE(ValidateLpipsWeights(kernel, "w").message().find("11x11"), std::string::npos);

  const Result<LpipsNet> net = LpipsNet::FromWeights(TinyWeights(6), "tiny");
  EXPECT_FALSE(net->Distance(RandomImage(20, 20, 1), RandomImage(20, 20, 2)).ok());  // too small
  EXPECT_FALSE(net->Distance(RandomImage(40, 40, 1), RandomImage(41, 40, 2)).ok());  // size mismatch
}

}  // namespace
}  // namespace icef::eval
