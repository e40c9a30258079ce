#include "icef/io/image.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "icef/io/atomic_file.h"
#include <stb_image_write.h>
#include <unistd.h>

namespace icef {
namespace {

namespace fs = std::filesystem;

fs::path TempDir(const std::string& name) {
  fs::path dir = fs::temp_directory_path() / ("icef_io_test_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

Image Gradient(int w, int h, int c) {
  Image img(w, h, c);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int k = 0; k < c; ++k) img.At(x, y, k) = static_cast<float>((x * 7 + y * 13 + k * 50) % 256) / 255.f;
  return img;
}

TEST(ImageTest, PngRoundTripIsExactFor8BitValues) {
  const fs::path dir = TempDir("roundtrip");
  for (int c : {1, 3, 4}) {
    Image img = Gradient(17, 9, c);
    const fs::path path = dir / ("img" + std::to_string(c) + ".png");
    ASSERT_TRUE(WritePng(path, img).ok());
    auto back = ReadImage(path);
    ASSERT_TRUE(back.ok()) << back.status().message();
    EXPECT_EQ(back->width, 17);
    EXPECT_EQ(back->height, 9);
    EXPECT_EQ(back->channels, c);
    for (size_t i = 0; i < img.pixels.size(); ++i) ASSERT_FLOAT_EQ(back->pixels[i], img.pixels[i]);
    auto info = ReadImageInfo(path);
    ASSERT_TRUE(info.ok());
    EXPECT_EQ(info->channels, c);
  }
  fs::remove_all(dir);
}

TEST(ImageTest, ReadsJpeg) {
  const fs::path dir = TempDir("jpeg");
  Image img(8, 8, 3, 0.5f);
  std::vector<unsigned char> bytes(8 * 8 * 3, 128);
  ASSERT_TRUE(stbi_write_jpg((dir / "a.jpg").c_str(), 8, 8, 3, bytes.data(), 95));
  auto back = ReadImage(dir / "a.jpg");
  ASSERT_TRUE(back.ok()) << back.status().message();
  EXPECT_EQ(back->channels, 3);
  EXPECT_NEAR(back->At(3, 3, 1), 128.f / 255.f, 2.f / 255.f);
  fs::remove_all(dir);
}

TEST(ImageTest, CompositingOverBackground) {
  Image rgba(2, 1, 4);
  rgba.At(0, 0, 0) = 1; rgba.At(0, 0, 3) = 1;     // opaque red
  rgba.At(1, 0, 0) = 1; rgba.At(1, 0, 3) = 0.25;  // quarter red over white
  Image rgb = CompositeOver(rgba, Vec3f(1, 1, 1));
  EXPECT_EQ(rgb.channels, 3);
  EXPECT_FLOAT_EQ(rgb.At(0, 0, 1), 0.f);
  EXPECT_FLOAT_EQ(rgb.At(1, 0, 0), 1.f);
  EXPECT_FLOAT_EQ(rgb.At(1, 0, 1), 0.75f);
  EXPECT_FLOAT_EQ(AlphaChannel(rgba).At(1, 0, 0), 0.25f);
}

TEST(ImageTest, BadFilesGiveErrorsNamingTheFile) {
  const fs::path dir = TempDir("bad");
  auto missing = ReadImage(dir / "missing.png");
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(missing.status().message().find("missing.png"), std::string::npos);
  std::ofstream(dir / "garbage.png") << "not an image at all";
  auto garbage = ReadImage(dir / "garbage.png");
  ASSERT_FALSE(garbage.ok());
  EXPECT_NE(garbage.status().message().find("garbage.png"), std::string::npos);
  std::ofstream(dir / "empty.png");
  EXPECT_FALSE(ReadImage(dir / "empty.png").ok());
  // Truncated PNG.
  const std::string png = EncodePng(Gradient(32, 32, 3));
  std::ofstream(dir / "trunc.png", std::ios::binary) << png.substr(0, png.size() / 2);
  EXPECT_FALSE(ReadImage(dir / "trunc.png").ok());
  fs::remove_all(dir);
}

TEST(AtomicFileTest, ReplacesWholeFileAndLeavesNoTemporaries) {
  const fs::path dir = TempDir("atomic");
  ASSERT_TRUE(WriteFileAtomic(dir / "f.txt", "first").ok());
  ASSERT_TRUE(WriteFileAtomic(dir / "f.txt", "second").ok());
  EXPECT_EQ(*ReadFile(dir / "f.txt"), "second");
  int count = 0;
  for (auto& e : fs::directory_iterator(dir)) (void)e, ++count;
  EXPECT_EQ(count, 1);
  EXPECT_FALSE(WriteFileAtomic(dir / "no_such_dir" / "f.txt", "x").ok());
  fs::remove_all(dir);
}

}  // namespace
}  // namespace icef
