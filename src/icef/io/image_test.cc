#include "icef/io/image.h"

#include <gtest/gtest.h>
#include <jpeglib.h>
#include <stb_image_write.h>
#include <unistd.h>
#include <zlib.h>

#include <cstdio>
#include <filesystem>
#include <fstream>

#include "icef/io/atomic_file.h"
#include "icef/io/image_decode.h"

namespace icef {
namespace {

namespace fs = std::filesystem;

fs::path TempDir(const std::string& name) {
  fs::path dir = fs::temp_directory_path() / ("icef_io_test_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

// A PNG built chunk by chunk (so tests can make what no encoder writes): `raw` is the unfiltered
// image data (each row prefixed by its filter byte 0), compressed into `idat_parts` IDAT chunks
// (the first of which may be empty); `before_idat` chunks (type + data) go after IHDR.
std::string Chunk(const std::string& type, const std::string& data) {
  auto be32 = [](uint32_t v) {
    const char b[4] = {char(v >> 24), char(v >> 16), char(v >> 8), char(v)};
    return std::string(b, 4);
  };
  const std::string body = type + data;
  return be32(uint32_t(data.size())) + body +
         be32(uint32_t(crc32(0, reinterpret_cast<const Bytef*>(body.data()), uInt(body.size()))));
}

std::string MakePng(int w, int h, int depth, int colour_type, const std::string& raw,
                    const std::vector<std::pair<std::string, std::string>>& before_idat = {},
                    bool empty_first_idat = false) {
  std::string ihdr(13, '\0');
  for (int k = 0; k < 4; ++k) {
    ihdr[k] = char(uint32_t(w) >> (24 - 8 * k));
    ihdr[4 + k] = char(uint32_t(h) >> (24 - 8 * k));
  }
  ihdr[8] = char(depth);
  ihdr[9] = char(colour_type);
  uLongf size = compressBound(uLong(raw.size()));
  std::string z(size, '\0');
  EXPECT_EQ(compress(reinterpret_cast<Bytef*>(z.data()), &size, reinterpret_cast<const Bytef*>(raw.data()),
                     uLong(raw.size())),
            Z_OK);
  z.resize(size);
  std::string png = "\x89PNG\r\n\x1a\n" + Chunk("IHDR", ihdr);
  for (const auto& [type, data] : before_idat) png += Chunk(type, data);
  if (empty_first_idat) png += Chunk("IDAT", "");
  return png + Chunk("IDAT", z) + Chunk("IEND", "");
}

// Rows of `bytes_per_row` bytes from `value(x_byte, y)`, each with filter byte 0.
template <typename F>
std::string RawRows(int h, int bytes_per_row, F value) {
  std::string raw;
  for (int y = 0; y < h; ++y) {
    raw += '\0';
    for (int i = 0; i < bytes_per_row; ++i) raw += char(value(i, y));
  }
  return raw;
}

fs::path WriteBytes(const fs::path& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary) << bytes;
  return path;
}

Image Gradient(int w, int h, int c) {
  Image img(w, h, c);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int k = 0; k < c; ++k)
        img.At(x, y, k) = static_cast<float>((x * 7 + y * 13 + k * 50) % 256) / 255.f;
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
  rgba.At(0, 0, 0) = 1;
  rgba.At(0, 0, 3) = 1;  // opaque red
  rgba.At(1, 0, 0) = 1;
  rgba.At(1, 0, 3) = 0.25;  // quarter red over white
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

TEST(ImageTest, SixteenBitGreyAlphaPaletteAndLowBitPngs) {
  const fs::path dir = TempDir("formats");
  // 16-bit RGB: big-endian samples in the file, [0, 1] floats exactly v / 65535.
  auto rgb16 = ReadImage(WriteBytes(
      dir / "rgb16.png", MakePng(3, 2, 16, 2, RawRows(2, 18, [](int i, int y) {
                                   return (i % 2 == 0) ? 0x12 + y
                                                       : 0x34 + i;  // sample = (0x12+y) << 8 | (0x34+i+1)
                                 }))));
  ASSERT_TRUE(rgb16.ok()) << rgb16.status().message();
  EXPECT_EQ(rgb16->channels, 3);
  EXPECT_FLOAT_EQ(rgb16->At(0, 0, 0), float(0x1235) / 65535.f);
  EXPECT_FLOAT_EQ(rgb16->At(2, 1, 2), float(0x1345) / 65535.f);
  // Grey stays one channel; grey + alpha becomes RGBA.
  auto grey = ReadImage(
      WriteBytes(dir / "grey.png", MakePng(4, 1, 8, 0, RawRows(1, 4, [](int i, int) { return 60 * i; }))));
  ASSERT_TRUE(grey.ok()) << grey.status().message();
  EXPECT_EQ(grey->channels, 1);
  EXPECT_FLOAT_EQ(grey->At(3, 0, 0), 180.f / 255.f);
  auto ga = ReadImage(
      WriteBytes(dir / "ga.png", MakePng(2, 1, 8, 4, RawRows(1, 4, [](int i, int) { return 10 + i; }))));
  ASSERT_TRUE(ga.ok()) << ga.status().message();
  EXPECT_EQ(ga->channels, 4);
  EXPECT_FLOAT_EQ(ga->At(1, 0, 1), 12.f / 255.f);
  EXPECT_FLOAT_EQ(ga->At(1, 0, 3), 13.f / 255.f);
  EXPECT_EQ(ReadImageInfo(dir / "ga.png")->channels, 2);
  // Palette with transparency -> RGBA; 1-bit grey -> 0 or 1.
  const std::string plte = std::string("\xff\x00\x00\x00\x00\xff", 6);
  auto pal =
      ReadImage(WriteBytes(dir / "pal.png", MakePng(2, 1, 8, 3, RawRows(1, 2, [](int i, int) { return i; }),
                                                    {{"PLTE", plte}, {"tRNS", std::string("\x80", 1)}})));
  ASSERT_TRUE(pal.ok()) << pal.status().message();
  EXPECT_EQ(pal->channels, 4);
  EXPECT_FLOAT_EQ(pal->At(0, 0, 0), 1.f);
  EXPECT_FLOAT_EQ(pal->At(0, 0, 3), 128.f / 255.f);
  EXPECT_FLOAT_EQ(pal->At(1, 0, 2), 1.f);
  EXPECT_FLOAT_EQ(pal->At(1, 0, 3), 1.f);
  auto bits = ReadImage(
      WriteBytes(dir / "bits.png", MakePng(8, 1, 1, 0, RawRows(1, 1, [](int, int) { return 0xA0; }))));
  ASSERT_TRUE(bits.ok()) << bits.status().message();
  EXPECT_EQ(bits->channels, 1);
  EXPECT_FLOAT_EQ(bits->At(0, 0, 0), 1.f);
  EXPECT_FLOAT_EQ(bits->At(1, 0, 0), 0.f);
  EXPECT_FLOAT_EQ(bits->At(2, 0, 0), 1.f);
  // An empty first IDAT chunk is legal (stb_image passed memcpy a null pointer for it).
  auto empty_idat = ReadImage(
      WriteBytes(dir / "empty_idat.png",
                 MakePng(4, 4, 8, 2, RawRows(4, 12, [](int i, int y) { return i * 20 + y; }), {}, true)));
  ASSERT_TRUE(empty_idat.ok()) << empty_idat.status().message();
  EXPECT_FLOAT_EQ(empty_idat->At(3, 2, 1), float(10 * 20 + 2) / 255.f);
  fs::remove_all(dir);
}

// A JPEG written with libjpeg in CMYK (Adobe convention: stored inverted, 255 = no ink).
std::string CmykJpeg(int w, int h, uint8_t c, uint8_t m, uint8_t y, uint8_t k) {
  jpeg_compress_struct cinfo;
  jpeg_error_mgr err;
  cinfo.err = jpeg_std_error(&err);
  jpeg_create_compress(&cinfo);
  unsigned char* buffer = nullptr;
  unsigned long size = 0;
  jpeg_mem_dest(&cinfo, &buffer, &size);
  cinfo.image_width = w;
  cinfo.image_height = h;
  cinfo.input_components = 4;
  cinfo.in_color_space = JCS_CMYK;
  jpeg_set_defaults(&cinfo);
  jpeg_set_quality(&cinfo, 100, TRUE);
  jpeg_start_compress(&cinfo, TRUE);
  std::vector<unsigned char> row(size_t(w) * 4);
  for (int x = 0; x < w; ++x) {
    row[x * 4] = c;
    row[x * 4 + 1] = m;
    row[x * 4 + 2] = y;
    row[x * 4 + 3] = k;
  }
  while (cinfo.next_scanline < cinfo.image_height) {
    JSAMPROW r = row.data();
    jpeg_write_scanlines(&cinfo, &r, 1);
  }
  jpeg_finish_compress(&cinfo);
  jpeg_destroy_compress(&cinfo);
  std::string out(reinterpret_cast<char*>(buffer), size);
  std::free(buffer);
  return out;
}

TEST(ImageTest, ReadsCmykJpegAsRgb) {
  const fs::path dir = TempDir("cmyk");
  auto img = ReadImage(WriteBytes(dir / "cmyk.jpg", CmykJpeg(16, 8, 255, 128, 0, 200)));
  ASSERT_TRUE(img.ok()) << img.status().message();
  EXPECT_EQ(img->channels, 3);
  EXPECT_NEAR(img->At(5, 5, 0), 200.f / 255.f, 3.f / 255.f);  // c * k / 255
  EXPECT_NEAR(img->At(5, 5, 1), 128.f * 200.f / 255.f / 255.f, 3.f / 255.f);
  EXPECT_NEAR(img->At(5, 5, 2), 0.f, 3.f / 255.f);
  EXPECT_EQ(ReadImageInfo(dir / "cmyk.jpg")->channels, 3);
  fs::remove_all(dir);
}

TEST(ImageTest, HeaderReadRefusesTruncatedAndCorruptFiles) {
  // ReadImageInfo (what `icef info` and the dataset loader use) checks the file's structure, so
  // damage is found without decoding; ReadImage refuses the same files.
  const fs::path dir = TempDir("structure");
  const std::string png = EncodePng(Gradient(32, 32, 3));
  auto refused = [&](const std::string& name, const std::string& bytes, const std::string& why) {
    const fs::path path = WriteBytes(dir / name, bytes);
    for (bool decode : {false, true}) {
      const Status s = decode ? ReadImage(path).status() : ReadImageInfo(path).status();
      ASSERT_FALSE(s.ok()) << name << " accepted (decode=" << decode << ")";
      EXPECT_NE(s.message().find(path.string()), std::string::npos) << s.message();
      EXPECT_NE(s.message().find(why), std::string::npos) << s.message();
    }
  };
  refused("header_only.png", png.substr(0, 40), "truncated");
  refused("cut_idat.png", png.substr(0, png.size() - 30), "truncated");
  refused("no_iend.png", png.substr(0, png.size() - 12), "before IEND");
  std::string flipped = png;
  flipped[60] = char(flipped[60] ^ 0x10);  // inside IDAT
  refused("flipped.png", flipped, "CRC error in chunk 'IDAT'");
  refused("no_idat.png", png.substr(0, 33) + Chunk("IEND", ""), "no IDAT");
  refused("text.png", "this is not a PNG\n", "not a PNG or JPEG");
  refused("empty.png", "", "empty file");
  // A header that claims more pixels than the compressed data can hold is refused before any
  // pixel buffer exists (it would be 768 MiB of floats).
  refused("huge.png", MakePng(16384, 4096, 8, 2, RawRows(1, 3, [](int, int) { return 0; })), "cannot hold");
  refused("wide.png", MakePng(20000, 1, 8, 0, RawRows(1, 20000, [](int, int) { return 0; })),
          "unsupported image size");

  std::vector<unsigned char> rgb(64 * 64 * 3);
  for (size_t i = 0; i < rgb.size(); ++i) rgb[i] = uint8_t(i * 31 % 251);
  ASSERT_TRUE(stbi_write_jpg((dir / "a.jpg").c_str(), 64, 64, 3, rgb.data(), 90));
  const std::string jpg = *ReadFile(dir / "a.jpg");
  ASSERT_TRUE(ReadImage(dir / "a.jpg").ok());
  refused("cut.jpg", jpg.substr(0, jpg.size() / 2), "corrupt JPEG: truncated");
  refused("no_eoi.jpg", jpg.substr(0, jpg.size() - 2), "corrupt JPEG: truncated");
  fs::remove_all(dir);
}

TEST(ImageTest, CorruptJpegDataIsAnErrorNotGreyPixels) {
  // libjpeg decodes damaged entropy data with a warning and fills in grey; here that is an error.
  const fs::path dir = TempDir("jpeg_data");
  std::vector<unsigned char> rgb(64 * 64 * 3);
  for (size_t i = 0; i < rgb.size(); ++i) rgb[i] = uint8_t(i * 31 % 251);
  ASSERT_TRUE(stbi_write_jpg((dir / "a.jpg").c_str(), 64, 64, 3, rgb.data(), 90));
  std::string jpg = *ReadFile(dir / "a.jpg");
  // Replace the second half of the scan data with a run of restart markers: structurally valid
  // (the marker walk reaches EOI), but the data segment ends early.
  const size_t sos = jpg.rfind("\xff\xda");
  ASSERT_NE(sos, std::string::npos);
  const size_t start = sos + (jpg.size() - sos) / 2;
  for (size_t i = start; i + 1 < jpg.size() - 2; i += 2) {
    jpg[i] = char(0xFF);
    jpg[i + 1] = char(0xD0);
  }
  const Status s = ReadImage(WriteBytes(dir / "damaged.jpg", jpg)).status();
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.message().find("damaged.jpg: corrupt JPEG"), std::string::npos) << s.message();
  fs::remove_all(dir);
}

// Every committed seed of the image fuzzer (fuzz/corpus/image/), among them the fuzzers' former
// findings against stb_image: a JPEG whose Huffman counts overflow its table (out-of-bounds
// write), a PNG with an empty IDAT (memcpy from NULL), a 175-byte PNG whose header asks for 2 GiB.
// Each gives a consistent image or an error naming the file; under `make sanitize` also no
// sanitizer report.
TEST(ImageTest, FuzzCorpusRegressionSeeds) {
  const fs::path corpus = fs::path(ICEF_SOURCE_DIR) / "fuzz" / "corpus" / "image";
  ASSERT_TRUE(fs::is_directory(corpus)) << corpus;
  int files = 0, decoded = 0;
  for (const auto& entry : fs::directory_iterator(corpus)) {
    ++files;
    const fs::path path = entry.path();
    const Result<ImageInfo> info = ReadImageInfo(path);
    const Result<Image> image = ReadImage(path);
    if (!image.ok()) {
      EXPECT_NE(image.status().message().find(path.string()), std::string::npos) << image.status().message();
      continue;
    }
    ++decoded;
    ASSERT_TRUE(info.ok()) << path << ": decodes but its header read fails: " << info.status().message();
    EXPECT_EQ(info->width, image->width) << path;
    EXPECT_EQ(info->height, image->height) << path;
    ASSERT_EQ(image->pixels.size(), size_t(image->width) * image->height * image->channels) << path;
    for (float v : image->pixels) ASSERT_TRUE(v >= 0.f && v <= 1.f) << path;
  }
  EXPECT_GE(files, 15);
  EXPECT_GE(decoded, 9);
  auto refused_with = [&](const char* name, const char* why) {
    const Status s = ReadImage(corpus / name).status();
    ASSERT_FALSE(s.ok()) << name;
    EXPECT_NE(s.message().find(why), std::string::npos) << s.message();
  };
  // The fuzzer's findings as found (stb_image ignored the CRCs they break) ...
  refused_with("stb_jpeg_huffman_overflow.jpg", "corrupt JPEG");
  refused_with("png_header_16777216x8_alloc_2gb.png", "CRC error in chunk 'IHDR'");
  refused_with("png_empty_idat_memcpy_null.png", "CRC error in chunk 'IHDR'");
  refused_with("truncated_idat.png", "corrupt PNG: truncated file");
  // ... and remade with valid structure, so that they reach libjpeg and libpng.
  refused_with("jpeg_dht_counts_over_256.jpg", "corrupt JPEG: Bogus Huffman table definition");
  refused_with("png_header_16777216x8_valid_crc.png", "unsupported image size 16777216x8");
  const Result<Image> empty_idat = ReadImage(corpus / "png_empty_first_idat.png");
  ASSERT_TRUE(empty_idat.ok()) << empty_idat.status().message();
  EXPECT_FLOAT_EQ(empty_idat->At(3, 2, 1), float(10 * 20 + 2) / 255.f);
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

TEST(AtomicFileTest, NewDirectoryIsAllOrNothing) {
  const fs::path dir = TempDir("atomic_dir");
  auto count = [](const fs::path& d) {
    int n = 0;
    for (auto& e : fs::directory_iterator(d)) (void)e, ++n;
    return n;
  };
  // Filled and moved into place; an empty directory may be taken over.
  fs::create_directories(dir / "empty");
  for (const char* name : {"new", "empty"}) {
    ASSERT_TRUE(CreateDirectoryAtomic(dir / name, [](const fs::path& tmp) {
                  return WriteFileAtomic(tmp / "a.txt", "a");
                }).ok());
    EXPECT_EQ(*ReadFile(dir / name / "a.txt"), "a");
  }
  // A directory with something in it is refused and left alone.
  const Status refused = CreateDirectoryAtomic(dir / "new", [](const fs::path&) { return Status::Ok(); });
  EXPECT_NE(refused.message().find("already exists"), std::string::npos);
  EXPECT_EQ(*ReadFile(dir / "new" / "a.txt"), "a");
  // A failing fill leaves neither the directory nor its temporary.
  const Status failed = CreateDirectoryAtomic(dir / "failed", [](const fs::path& tmp) {
    (void)WriteFileAtomic(tmp / "half.txt", "x");
    return Status::Error("fill failed");
  });
  EXPECT_EQ(failed.message(), "fill failed");
  EXPECT_FALSE(fs::exists(dir / "failed"));
  EXPECT_EQ(count(dir), 2);  // new, empty
  fs::remove_all(dir);
}

}  // namespace
}  // namespace icef
