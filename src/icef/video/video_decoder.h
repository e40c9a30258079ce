// Internal to the video module: one video stream decoded frame by frame, each frame available as
// 8-bit RGB turned upright. ReadVideoFrames and ProbeVideo are built on it.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <vector>

#include "icef/core/status.h"
#include "icef/io/image.h"
#include "icef/video/libav_util.h"
#include "icef/video/video_reader.h"

namespace icef {

// 8-bit RGB (a quarter of an Image's memory, for frames held while decoding goes on).
struct Rgb8Frame {
  int width = 0;             // pixels
  int height = 0;            // pixels
  std::vector<uint8_t> rgb;  // [height, width, 3], row 0 at the top
  Image ToImage() const;     // RGB, values / 255
};

// `frame` turned clockwise by `degrees` (0, 90, 180 or 270).
Rgb8Frame RotateClockwise(const Rgb8Frame& frame, int degrees);

class VideoDecoder {
 public:
  // Opens `path`, picks its best video stream and readies a decoder. Errors name the file.
  static Result<std::unique_ptr<VideoDecoder>> Open(const std::filesystem::path& path);

  const VideoInfo& info() const { return info_; }
  // Decodes the next frame: true when there is one (see index(), time_s(), CurrentRgb()), false
  // at the end of the stream, also when the file breaks off after some frames were decoded. An
  // error when the stream ends before any frame could be decoded. Damaged packets are skipped.
  Result<bool> Next();
  int64_t index() const { return index_; }  // the current frame's number, from 0 (-1 before the first)
  double time_s() const;                    // the current frame's presentation time from the stream start
  // The current frame as 8-bit RGB, upright.
  Result<Rgb8Frame> CurrentRgb();

 private:
  VideoDecoder() = default;
  Status Error(const std::string& what) const;  // "<file>: <what>"
  Result<bool> Finish();

  std::filesystem::path path_;
  VideoInfo info_;
  libav::InputPtr format_;
  libav::CodecPtr codec_;
  libav::FramePtr frame_;
  libav::PacketPtr packet_;
  libav::SwsPtr sws_;
  int sws_key_[5] = {-1, -1, -1, -1, -1};  // width, height, format, colour space, range sws_ converts
  int stream_index_ = -1;
  double time_base_ = 0;   // seconds per stream tick
  int64_t start_pts_ = 0;  // the stream's first timestamp
  int64_t index_ = -1;
  bool flushing_ = false;  // the input is exhausted and the decoder is being drained
  bool ended_ = false;
  int last_error_ = 0;  // the last libav error met while reading or decoding (0: none)
};

}  // namespace icef
