#include "icef/eval/metrics.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "icef/core/rng.h"
#include "icef/io/atomic_file.h"

namespace icef::eval {
namespace {

namespace fs = std::filesystem;
const fs::path kFixtureDir = fs::path(ICEF_SOURCE_DIR) / "tests" / "fixtures" / "ssim";

Image Load(const std::string& name) {
  Result<Image> image = ReadImage(kFixtureDir / name);
  EXPECT_TRUE(image.ok()) << image.status().message();
  return image.ok() ? *image : Image();
}

// Values computed by skimage 0.19.3 (scripts/make_ssim_fixture.py) on the committed pairs.
TEST(MetricsTest, MatchesSkimageOnFixturePairs) {
  const Result<std::string> text = ReadFile(kFixtureDir / "expected.json");
  ASSERT_TRUE(text.ok()) << text.status().message();
  const nlohmann::json expected = nlohmann::json::parse(*text);
  ASSERT_GE(expected["pairs"].size(), 4u);
  for (const auto& pair : expected["pairs"]) {
    SCOPED_TRACE(pair["name"].get<std::string>());
    const Image a = Load(pair["a"]), b = Load(pair["b"]), mask = Load(pair["mask"]);
    ASSERT_EQ(a.channels, 3);
    const Result<double> psnr = Psnr(a, b), ssim = Ssim(a, b);
    const Result<double> psnr_m = Psnr(a, b, &mask), ssim_m = Ssim(a, b, {}, &mask);
    ASSERT_TRUE(psnr.ok() && ssim.ok() && psnr_m.ok() && ssim_m.ok());
    EXPECT_NEAR(*psnr, pair["psnr"].get<double>(), 1e-6);
    EXPECT_NEAR(*ssim, pair["ssim"].get<double>(), 1e-6);
    EXPECT_NEAR(*psnr_m, pair["psnr_masked"].get<double>(), 1e-6);
    EXPECT_NEAR(*ssim_m, pair["ssim_masked"].get<double>(), 1e-6);
  }
}

Image RandomImage(int w, int h, int c, uint64_t item) {
  Rng rng(11, StreamId("metrics_test"), 0, item);
  Image image(w, h, c);
  for (float& v : image.pixels) v = rng.Uniform();
  return image;
}

TEST(MetricsTest, IdentityAndSymmetry) {
  const Image a = RandomImage(16, 13, 3, 1), b = RandomImage(16, 13, 3, 2);
  EXPECT_TRUE(std::isinf(*Psnr(a, a)));
  EXPECT_NEAR(*Ssim(a, a), 1.0, 1e-12);
  EXPECT_NEAR(*Ssim(a, b), *Ssim(b, a), 1e-12);
  EXPECT_LT(*Ssim(a, b), 0.5);
  // Uniform offset of 0.1 on every value: MSE 0.01 -> 20 dB.
  Image c = a;
  for (float& v : c.pixels) v += 0.1f;
  EXPECT_NEAR(*Psnr(a, c), 20.0, 1e-4);
}

TEST(MetricsTest, AlphaIsIgnoredAndGreyWorks) {
  Image a = RandomImage(12, 12, 4, 3), b = RandomImage(12, 12, 4, 4);
  const double base = *Ssim(a, b);
  for (int y = 0; y < 12; ++y)
    for (int x = 0; x < 12; ++x) a.At(x, y, 3) = 0.f;
  EXPECT_EQ(*Ssim(a, b), base);
  const Image g1 = RandomImage(12, 12, 1, 5), g2 = RandomImage(12, 12, 1, 6);
  EXPECT_TRUE(Ssim(g1, g2).ok());
  EXPECT_TRUE(Psnr(g1, g2).ok());
}

TEST(MetricsTest, MaskRestrictsToForeground) {
  // Images equal inside the left half, different on the right: masked to the left half, PSNR is
  // infinite and SSIM (on pixels whose window stays inside the left half) is 1.
  Image a = RandomImage(30, 20, 3, 7), b = RandomImage(30, 20, 3, 8);
  Image mask(30, 20, 1, 0.f);
  for (int y = 0; y < 20; ++y)
    for (int x = 0; x < 15; ++x) {
      mask.At(x, y, 0) = x < 10 ? 1.f : 0.f;
      for (int c = 0; c < 3; ++c) b.At(x, y, c) = a.At(x, y, c);
    }
  EXPECT_TRUE(std::isinf(*Psnr(a, b, &mask)));
  EXPECT_NEAR(*Ssim(a, b, {}, &mask), 1.0, 1e-12);
  EXPECT_LT(*Ssim(a, b), 0.9);
}

TEST(MetricsTest, ErrorsNameTheProblem) {
  const Image a = RandomImage(12, 12, 3, 9), small = RandomImage(8, 12, 3, 10);
  EXPECT_NE(Ssim(a, small).status().message().find("differ"), std::string::npos);
  EXPECT_NE(Ssim(small, small).status().message().find("window"), std::string::npos);
  const Image empty_mask(12, 12, 1, 0.f);
  EXPECT_FALSE(Psnr(a, a, &empty_mask).ok());
  EXPECT_FALSE(Ssim(a, a, {}, &empty_mask).ok());
  SsimOptions bad;
  bad.sigma = 0.0;
  EXPECT_FALSE(Ssim(a, a, bad).ok());
}

// A textured "face" (fine noise over a smooth gradient), the same blurred (detail lost), and the
// same with extra pixel noise (more edges than the truth).
TEST(MetricsTest, DetailRatioSeesBlurAndNoise) {
  const int n = 64;
  Image truth(n, n, 3), blurred(n, n, 3), noisy(n, n, 3);
  Rng rng(3, StreamId("metrics_test.detail"));
  std::vector<float> noise(n * n);
  for (float& v : noise) v = static_cast<float>(rng.Uniform(-0.08, 0.08));
  auto base = [&](int x, int y) { return 0.3f + 0.4f * x / n; };
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      float sum = 0.f;
      int count = 0;
      for (int dy = -2; dy <= 2; ++dy)
        for (int dx = -2; dx <= 2; ++dx) {
          const int xx = std::clamp(x + dx, 0, n - 1), yy = std::clamp(y + dy, 0, n - 1);
          sum += noise[yy * n + xx], ++count;
        }
      const float extra = static_cast<float>(rng.Uniform(-0.08, 0.08));
      for (int c = 0; c < 3; ++c) {
        truth.At(x, y, c) = base(x, y) + noise[y * n + x];
        blurred.At(x, y, c) = base(x, y) + sum / count;
        noisy.At(x, y, c) = truth.At(x, y, c) + extra;
      }
    }
  EXPECT_DOUBLE_EQ(*DetailRatio(truth, truth), 1.0);
  const double blur = *DetailRatio(blurred, truth);
  EXPECT_LT(blur, 0.3);
  EXPECT_GT(*DetailRatio(noisy, truth), 1.3);  // independent noise of the same amplitude: ~sqrt(2)
  // Masked: only the left half counts.
  Image mask(n, n, 1, 0.f);
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n / 2; ++x) mask.At(x, y, 0) = 1.f;
  EXPECT_NEAR(*DetailRatio(blurred, truth, &mask), blur, 0.1);
  EXPECT_FALSE(DetailRatio(truth, Image(n, n, 3, 0.5f)).ok());  // a flat truth has no detail
  EXPECT_FALSE(DetailRatio(truth, Image(n / 2, n, 3)).ok());
}

}  // namespace
}  // namespace icef::eval
