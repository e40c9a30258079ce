#include "icef/io/gif_writer.h"

#include <gif_lib.h>
#include <gtest/gtest.h>

#include <cstring>

namespace icef {
namespace {

struct Reader {
  const std::string* bytes;
  size_t pos = 0;
};

int ReadFromString(GifFileType* gif, GifByteType* out, int size) {
  auto* r = static_cast<Reader*>(gif->UserData);
  const int n = static_cast<int>(std::min<size_t>(size, r->bytes->size() - r->pos));
  std::memcpy(out, r->bytes->data() + r->pos, n);
  r->pos += n;
  return n;
}

TEST(GifWriterTest, DecodesBackToTheFramesColours) {
  std::vector<Image> frames;
  for (int k = 0; k < 3; ++k) {
    Image img(16, 8, 3);
    for (int y = 0; y < 8; ++y)
      for (int x = 0; x < 16; ++x) {
        img.At(x, y, 0) = x < 8 ? 1.f : 0.f;
        img.At(x, y, 1) = float(k) / 2.f;
        img.At(x, y, 2) = y < 4 ? 0.25f : 0.75f;
      }
    frames.push_back(img);
  }
  auto gif = EncodeGif(frames, 5);
  ASSERT_TRUE(gif.ok()) << gif.status().message();
  Reader reader{&*gif};
  int error = 0;
  GifFileType* in = DGifOpen(&reader, ReadFromString, &error);
  ASSERT_NE(in, nullptr);
  ASSERT_EQ(DGifSlurp(in), GIF_OK);
  EXPECT_EQ(in->ImageCount, 3);
  EXPECT_EQ(in->SWidth, 16);
  for (int k = 0; k < 3; ++k) {
    const SavedImage& s = in->SavedImages[k];
    const ColorMapObject* map = s.ImageDesc.ColorMap ? s.ImageDesc.ColorMap : in->SColorMap;
    ASSERT_NE(map, nullptr);
    for (int y = 0; y < 8; ++y)
      for (int x = 0; x < 16; ++x) {
        const GifColorType c = map->Colors[s.RasterBits[y * 16 + x]];
        EXPECT_NEAR(c.Red / 255.f, frames[k].At(x, y, 0), 0.05f);
        EXPECT_NEAR(c.Green / 255.f, frames[k].At(x, y, 1), 0.05f);
        EXPECT_NEAR(c.Blue / 255.f, frames[k].At(x, y, 2), 0.05f);
      }
  }
  DGifCloseFile(in, &error);
  EXPECT_FALSE(EncodeGif({}, 5).ok());
}

}  // namespace
}  // namespace icef
