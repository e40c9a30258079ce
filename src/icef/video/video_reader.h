// Reading video files (MP4, MOV, MKV, AVI, WebM, ... whatever Debian's libavformat/libavcodec
// decode) as RGB frames, for `icef track` on a video. Frames are turned upright by the stream's
// display-rotation tag (phone videos). Every failure is a Status with one line naming the file;
// libav's own log output is silenced.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "icef/core/status.h"
#include "icef/io/image.h"

namespace icef {

struct VideoInfo {
  int width = 0;                     // frame width in pixels, upright (after `rotation`)
  int height = 0;                    // frame height in pixels, upright (after `rotation`)
  double fps = 0;                    // frames per second (the stream's guessed frame rate; 0 if unknown)
  double duration_s = 0;             // length in seconds (0 if the container does not say)
  int64_t frame_count_estimate = 0;  // the container's frame count, else duration_s * fps (0 if unknown)
  std::string codec;                 // codec name, e.g. "h264", "hevc", "vp9"
  int rotation = 0;                  // clockwise degrees (0, 90, 180, 270) the stored frames are turned by
  std::string ToString() const;
};

// Opens the file and reads its header (no full decode). Errors name the file.
Result<VideoInfo> ProbeVideo(const std::filesystem::path& path);

struct VideoFrame {
  Image image;        // RGB, upright, values in [0, 1]
  int64_t index = 0;  // decoded frame number, from 0
  double time_s = 0;  // presentation time from the start of the stream, in seconds
};

struct VideoReadOptions {
  int every = 0;       // keep every N-th decoded frame; 0: all, or max_frames spread over the video
  int max_frames = 0;  // at most this many frames (0: no limit); with every > 0, the first ones
  Status Validate() const;
  std::string ToString() const;
};

// Decodes the best video stream of `path` and returns the frames the options keep, in order.
// With every == 0 and max_frames > 0 the frames are spread evenly over the whole video: chosen by
// the container's frame-count estimate while decoding, and, when the estimate proves wrong, from a
// bounded evenly-thinned reserve (at most about 3 * max_frames frames are held, as 8-bit RGB).
// A video that breaks off part-way yields the frames decoded before the break; one from which no
// frame can be decoded is an error. `progress` (optional) is called after each decoded frame with
// (frames decoded so far, frame_count_estimate or 0).
Result<std::vector<VideoFrame>> ReadVideoFrames(
    const std::filesystem::path& path, const VideoReadOptions& options,
    const std::function<void(int64_t decoded, int64_t total_estimate)>& progress = nullptr);

// Whether the file name has a video extension: .mp4 .mov .mkv .avi .webm .m4v (any case).
bool LooksLikeVideo(const std::filesystem::path& path);

}  // namespace icef
