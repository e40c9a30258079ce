#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "icef/io/atomic_file.h"
#include "icef/video/frame_sampler.h"
#include "icef/video/video_reader.h"
#include "icef/video/video_writer.h"

namespace icef {
namespace {

namespace fs = std::filesystem;

constexpr int kFrames = 40;
constexpr int kWidth = 64;
constexpr int kHeight = 48;

// Frame `i` of the test clip: a gradient with a square moving right and down.
Image ClipFrame(int i, int width = kWidth, int height = kHeight) {
  Image image(width, height, 3);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const bool square = x >= 2 + i && x < 14 + i && y >= 4 + i / 2 && y < 16 + i / 2;
      image.At(x, y, 0) = square ? 0.9f : float(x) / width;
      image.At(x, y, 1) = square ? 0.2f : float(y) / height;
      image.At(x, y, 2) = square ? 0.1f : 0.3f;
    }
  }
  return image;
}

std::vector<Image> Clip(int frames = kFrames) {
  std::vector<Image> clip;
  for (int i = 0; i < frames; ++i) clip.push_back(ClipFrame(i));
  return clip;
}

double MeanAbsDiff(const Image& a, const Image& b) {
  EXPECT_EQ(a.width, b.width);
  EXPECT_EQ(a.height, b.height);
  EXPECT_EQ(a.channels, b.channels);
  if (a.pixels.size() != b.pixels.size()) return 1;
  double sum = 0;
  for (size_t i = 0; i < a.pixels.size(); ++i) sum += std::abs(a.pixels[i] - b.pixels[i]);
  return sum / a.pixels.size();
}

Image RotateClockwise90(const Image& image) {
  Image out(image.height, image.width, image.channels);
  for (int y = 0; y < out.height; ++y)
    for (int x = 0; x < out.width; ++x)
      for (int c = 0; c < image.channels; ++c) out.At(x, y, c) = image.At(y, image.height - 1 - x, c);
  return out;
}

// Asserts a failed Status with a one-line message naming `file`.
void ExpectErrorNaming(const Status& status, const fs::path& file) {
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find(file.filename().string()), std::string::npos) << status.message();
  EXPECT_EQ(status.message().find('\n'), std::string::npos) << status.message();
}

class VideoTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = fs::temp_directory_path() / ("icef_video_test_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    clip_ = dir_ / "clip.mp4";
    VideoWriter writer;
    ASSERT_TRUE(writer.Open(clip_, kWidth, kHeight, {}).ok());
    encoder_ = writer.encoder();
    for (const Image& frame : Clip()) ASSERT_TRUE(writer.Add(frame).ok());
    ASSERT_TRUE(writer.Close().ok());
  }
  static void TearDownTestSuite() { fs::remove_all(dir_); }

  static inline fs::path dir_;
  static inline fs::path clip_;
  static inline std::string encoder_;
};

TEST_F(VideoTest, WriterUsesLibx264WhenAvailable) {
  std::cout << "encoder: " << encoder_ << "\n";
  EXPECT_TRUE(encoder_ == "libx264" || encoder_ == "mpeg4") << encoder_;
  for (const auto& entry : fs::directory_iterator(dir_))
    EXPECT_EQ(entry.path().string().find(".tmp"), std::string::npos) << "left behind: " << entry.path();
}

TEST_F(VideoTest, ProbeGivesSizeRateAndFrameCount) {
  Result<VideoInfo> info = ProbeVideo(clip_);
  ASSERT_TRUE(info.ok()) << info.status().message();
  EXPECT_EQ(info->width, kWidth);
  EXPECT_EQ(info->height, kHeight);
  EXPECT_NEAR(info->fps, 25.0, 0.01);
  EXPECT_NEAR(double(info->frame_count_estimate), kFrames, 2);
  EXPECT_NEAR(info->duration_s, kFrames / 25.0, 0.1);
  EXPECT_EQ(info->codec, encoder_ == "libx264" ? "h264" : "mpeg4");
  EXPECT_EQ(info->rotation, 0);
  EXPECT_NE(info->ToString().find("64x48"), std::string::npos);
}

TEST_F(VideoTest, ReadsEveryFrameInOrderWithTheWrittenColours) {
  int64_t last_decoded = 0, last_total = -1;
  Result<std::vector<VideoFrame>> frames = ReadVideoFrames(clip_, {}, [&](int64_t decoded, int64_t total) {
    EXPECT_EQ(decoded, last_decoded + 1);
    last_decoded = decoded;
    last_total = total;
  });
  ASSERT_TRUE(frames.ok()) << frames.status().message();
  ASSERT_EQ(frames->size(), size_t(kFrames));
  EXPECT_EQ(last_decoded, kFrames);
  EXPECT_EQ(last_total, kFrames);
  for (int i = 0; i < kFrames; ++i) {
    const VideoFrame& f = (*frames)[i];
    EXPECT_EQ(f.index, i);
    EXPECT_NEAR(f.time_s, i / 25.0, 1e-3);
    if (i > 0) {
      EXPECT_GT(f.time_s, (*frames)[i - 1].time_s);
    }
    ASSERT_EQ(f.image.channels, 3);
    EXPECT_LT(MeanAbsDiff(f.image, ClipFrame(i)), 0.03) << "frame " << i;
  }
}

TEST_F(VideoTest, EveryKeepsEveryNthFrame) {
  Result<std::vector<VideoFrame>> frames = ReadVideoFrames(clip_, {.every = 4});
  ASSERT_TRUE(frames.ok()) << frames.status().message();
  ASSERT_EQ(frames->size(), size_t(kFrames / 4));
  for (size_t k = 0; k < frames->size(); ++k) EXPECT_EQ((*frames)[k].index, int64_t(4 * k));

  frames = ReadVideoFrames(clip_, {.every = 3, .max_frames = 4});  // the first four of every third
  ASSERT_TRUE(frames.ok()) << frames.status().message();
  ASSERT_EQ(frames->size(), 4u);
  EXPECT_EQ((*frames)[3].index, 9);
}

TEST_F(VideoTest, MaxFramesSpreadOverTheWholeClip) {
  Result<std::vector<VideoFrame>> frames = ReadVideoFrames(clip_, {.max_frames = 5});
  ASSERT_TRUE(frames.ok()) << frames.status().message();
  ASSERT_EQ(frames->size(), 5u);
  EXPECT_LE(frames->front().index, 1);
  EXPECT_GE(frames->back().index, kFrames - 2);
  for (size_t k = 0; k < frames->size(); ++k) {
    const VideoFrame& f = (*frames)[k];
    if (k > 0) {
      EXPECT_GT(f.index, (*frames)[k - 1].index);
    }
    EXPECT_NEAR(double(f.index), k * (kFrames - 1) / 4.0, 1.0);
    EXPECT_NEAR(f.time_s, f.index / 25.0, 1e-3);
    EXPECT_LT(MeanAbsDiff(f.image, ClipFrame(int(f.index))), 0.03) << "frame " << f.index;
  }
  frames = ReadVideoFrames(clip_, {.max_frames = 100});  // more than there are: all of them
  ASSERT_TRUE(frames.ok()) << frames.status().message();
  EXPECT_EQ(frames->size(), size_t(kFrames));
}

TEST_F(VideoTest, TruncatedFileIsAnErrorNamingIt) {
  Result<std::string> bytes = ReadFile(clip_);
  ASSERT_TRUE(bytes.ok());
  const fs::path cut = dir_ / "cut.mp4";
  ASSERT_TRUE(WriteFileAtomic(cut, bytes->substr(0, bytes->size() * 3 / 10)).ok());
  ExpectErrorNaming(ReadVideoFrames(cut, {}).status(), cut);
  ExpectErrorNaming(ProbeVideo(cut).status(), cut);
}

TEST_F(VideoTest, TextFileIsAnErrorNamingIt) {
  const fs::path text = dir_ / "notes.mp4";
  ASSERT_TRUE(WriteFileAtomic(text, "These are notes about the shoot, not a video.\nSecond line.\n").ok());
  ExpectErrorNaming(ReadVideoFrames(text, {.max_frames = 3}).status(), text);
  ExpectErrorNaming(ProbeVideo(text).status(), text);
  const fs::path missing = dir_ / "missing.mp4";
  ExpectErrorNaming(ReadVideoFrames(missing, {}).status(), missing);
}

TEST_F(VideoTest, OddFrameSizeIsAnErrorNamingTheField) {
  const fs::path out = dir_ / "odd.mp4";
  Status status = WriteVideo(out, {ClipFrame(0, 63, 48)}, {});
  ExpectErrorNaming(status, out);
  EXPECT_NE(status.message().find("width"), std::string::npos) << status.message();
  EXPECT_NE(status.message().find("63"), std::string::npos) << status.message();
  status = WriteVideo(out, {ClipFrame(0, 64, 47)}, {});
  EXPECT_NE(status.message().find("height"), std::string::npos) << status.message();
  EXPECT_FALSE(fs::exists(out));
}

TEST_F(VideoTest, FailedWriteLeavesTheOldFileAndNoTemporary) {
  const fs::path out = dir_ / "keep.mp4";
  ASSERT_TRUE(WriteVideo(out, Clip(4)).ok());
  std::vector<Image> mixed = Clip(3);
  mixed.push_back(ClipFrame(3, 32, 48));
  const Status status = WriteVideo(out, mixed);
  ExpectErrorNaming(status, out);
  EXPECT_NE(status.message().find("32x48"), std::string::npos) << status.message();
  Result<std::vector<VideoFrame>> frames = ReadVideoFrames(out, {});
  ASSERT_TRUE(frames.ok()) << frames.status().message();
  EXPECT_EQ(frames->size(), 4u);
  ExpectErrorNaming(WriteVideo(out, {}), out);
  {
    VideoWriter abandoned;
    ASSERT_TRUE(abandoned.Open(dir_ / "abandoned.mp4", kWidth, kHeight, {}).ok());
    ASSERT_TRUE(abandoned.Add(ClipFrame(0)).ok());
  }
  for (const auto& entry : fs::directory_iterator(dir_))
    EXPECT_EQ(entry.path().string().find(".tmp"), std::string::npos) << "left behind: " << entry.path();
  EXPECT_FALSE(fs::exists(dir_ / "abandoned.mp4"));
}

TEST_F(VideoTest, Mpeg4EncoderRoundTrips) {
  const fs::path out = dir_ / "mpeg4.mp4";
  VideoWriter writer;
  ASSERT_TRUE(writer.Open(out, kWidth, kHeight, {.fps = 30, .codec = "mpeg4"}).ok());
  EXPECT_EQ(writer.encoder(), "mpeg4");
  for (const Image& frame : Clip(10)) ASSERT_TRUE(writer.Add(frame).ok());
  ASSERT_TRUE(writer.Close().ok());
  Result<VideoInfo> info = ProbeVideo(out);
  ASSERT_TRUE(info.ok()) << info.status().message();
  EXPECT_EQ(info->codec, "mpeg4");
  EXPECT_NEAR(info->fps, 30.0, 0.01);
  Result<std::vector<VideoFrame>> frames = ReadVideoFrames(out, {});
  ASSERT_TRUE(frames.ok()) << frames.status().message();
  ASSERT_EQ(frames->size(), 10u);
  for (const VideoFrame& f : *frames)
    EXPECT_LT(MeanAbsDiff(f.image, ClipFrame(int(f.index))), 0.03) << f.index;
}

TEST_F(VideoTest, RotationTagTurnsFramesUpright) {
  const fs::path out = dir_ / "portrait.mp4";
  ASSERT_TRUE(WriteVideo(out, Clip(3), {.rotation = 90}).ok());
  Result<VideoInfo> info = ProbeVideo(out);
  ASSERT_TRUE(info.ok()) << info.status().message();
  EXPECT_EQ(info->rotation, 90);
  EXPECT_EQ(info->width, kHeight);
  EXPECT_EQ(info->height, kWidth);
  Result<std::vector<VideoFrame>> frames = ReadVideoFrames(out, {});
  ASSERT_TRUE(frames.ok()) << frames.status().message();
  ASSERT_EQ(frames->size(), 3u);
  for (const VideoFrame& f : *frames)
    EXPECT_LT(MeanAbsDiff(f.image, RotateClockwise90(ClipFrame(int(f.index)))), 0.03) << f.index;
}

TEST(VideoOptionsTest, Validate) {
  EXPECT_TRUE(VideoReadOptions{}.Validate().ok());
  EXPECT_TRUE((VideoReadOptions{.every = 2, .max_frames = 10}.Validate().ok()));
  Status status = VideoReadOptions{.every = -1}.Validate();
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("every"), std::string::npos);
  status = VideoReadOptions{.max_frames = -3}.Validate();
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("max_frames"), std::string::npos);
  ExpectErrorNaming(ReadVideoFrames("clip.mp4", {.every = -1}).status(), "clip.mp4");

  EXPECT_TRUE(VideoWriteOptions{}.Validate().ok());
  EXPECT_NE(VideoWriteOptions{.fps = 0}.Validate().message().find("fps"), std::string::npos);
  EXPECT_NE(VideoWriteOptions{.crf = 52}.Validate().message().find("crf"), std::string::npos);
  EXPECT_NE(VideoWriteOptions{.codec = "hevc"}.Validate().message().find("codec"), std::string::npos);
  EXPECT_NE(VideoWriteOptions{.rotation = 45}.Validate().message().find("rotation"), std::string::npos);
}

TEST(VideoOptionsTest, LooksLikeVideoByExtension) {
  for (const char* name : {"a.mp4", "b.MOV", "dir/c.mkv", "d.Avi", "e.webm", "f.m4v"})
    EXPECT_TRUE(LooksLikeVideo(name)) << name;
  for (const char* name : {"a.png", "b.jpg", "mp4", "c.mp4.txt", ""})
    EXPECT_FALSE(LooksLikeVideo(name)) << name;
}

}  // namespace
}  // namespace icef
