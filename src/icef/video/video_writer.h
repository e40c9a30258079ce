// Writing MP4 video for `icef render --video` and the tests' clips: H.264 (libx264) when
// libavcodec has it, else MPEG-4 Part 2 (libavcodec's built-in "mpeg4"); yuv420p, so both frame
// dimensions must be even. The file is written beside the destination under a temporary name and
// renamed into place by Close, so a failed or abandoned write leaves nothing half-written.
#pragma once

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "icef/core/status.h"
#include "icef/io/image.h"

namespace icef {

struct VideoWriteOptions {
  double fps = 25;             // frames per second, in (0, 1000]
  int crf = 20;                // quality 0 (best) .. 51 (worst): libx264's CRF, mapped to a q-scale for mpeg4
  std::string codec = "auto";  // "auto" (libx264 if available, else mpeg4), "libx264" or "mpeg4"
  int rotation = 0;            // display-rotation tag, clockwise degrees 0/90/180/270; frames stored as given
  Status Validate() const;
  std::string ToString() const;
};

// Streaming form: Open, Add each frame, Close. Destroying an unclosed writer removes its temporary.
class VideoWriter {
 public:
  VideoWriter();
  ~VideoWriter();
  VideoWriter(const VideoWriter&) = delete;
  VideoWriter& operator=(const VideoWriter&) = delete;

  // Starts an MP4 at `out` for frames of width x height pixels (both even). Errors name `out`.
  Status Open(const std::filesystem::path& out, int width, int height, const VideoWriteOptions& options);
  // Encodes one frame of the opened size: RGB (grey repeated, alpha ignored), values clamped to [0, 1].
  Status Add(const Image& frame);
  // Drains the encoder, finishes the file and renames it to `out`; at least one frame is needed.
  Status Close();
  // The encoder in use after Open: "libx264" or "mpeg4".
  const std::string& encoder() const { return encoder_; }

 private:
  struct State;
  std::unique_ptr<State> state_;
  std::string encoder_;
};

// Writes `frames` (all of one size, both dimensions even) as an MP4 at `out`.
Status WriteVideo(const std::filesystem::path& out, const std::vector<Image>& frames,
                  const VideoWriteOptions& options = {});

}  // namespace icef
