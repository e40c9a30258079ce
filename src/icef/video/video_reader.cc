#include "icef/video/video_reader.h"

#include <algorithm>
#include <cctype>
#include <map>
#include <sstream>

#include "icef/video/frame_sampler.h"
#include "icef/video/video_decoder.h"

namespace icef {

namespace fs = std::filesystem;

std::string VideoInfo::ToString() const {
  std::ostringstream os;
  os << "VideoInfo(" << width << "x" << height << ", fps=" << fps << ", duration_s=" << duration_s
     << ", frame_count_estimate=" << frame_count_estimate << ", codec=" << codec << ", rotation=" << rotation
     << ")";
  return os.str();
}

Status VideoReadOptions::Validate() const {
  if (every < 0)
    return Status::Error("every must be >= 0 (0: all frames, or max_frames spread over the video), got " +
                         std::to_string(every));
  if (max_frames < 0)
    return Status::Error("max_frames must be >= 0 (0: no limit), got " + std::to_string(max_frames));
  return Status::Ok();
}

std::string VideoReadOptions::ToString() const {
  return "VideoReadOptions(every=" + std::to_string(every) + ", max_frames=" + std::to_string(max_frames) +
         ")";
}

Result<VideoInfo> ProbeVideo(const fs::path& path) {
  ICEF_ASSIGN_OR_RETURN(std::unique_ptr<VideoDecoder> decoder, VideoDecoder::Open(path));
  return decoder->info();
}

namespace {

struct HeldFrame {
  Rgb8Frame rgb;
  double time_s = 0;
};

// every == 0, max_frames > 0: frames spread evenly over the whole video (frame_sampler.h).
Result<std::vector<VideoFrame>> ReadSpread(VideoDecoder& decoder, int max_frames,
                                           const std::function<void(int64_t, int64_t)>& progress) {
  const int64_t total = decoder.info().frame_count_estimate;
  EvenFrameSampler sampler(max_frames, total);
  std::map<int64_t, HeldFrame> held;
  for (;;) {
    ICEF_ASSIGN_OR_RETURN(bool more, decoder.Next());
    if (!more) break;
    const int64_t i = decoder.index();
    if (sampler.Offer(i)) {
      ICEF_ASSIGN_OR_RETURN(Rgb8Frame rgb, decoder.CurrentRgb());
      held[i] = HeldFrame{std::move(rgb), decoder.time_s()};
    }
    for (int64_t r : sampler.TakeReleased()) held.erase(r);
    if (progress) progress(i + 1, total);
  }
  std::vector<VideoFrame> frames;
  for (int64_t i : sampler.Choose(decoder.index() + 1)) {
    HeldFrame& h = held.at(i);
    frames.push_back(VideoFrame{h.rgb.ToImage(), i, h.time_s});
    h.rgb = {};
  }
  return frames;
}

}  // namespace

Result<std::vector<VideoFrame>> ReadVideoFrames(const fs::path& path, const VideoReadOptions& options,
                                                const std::function<void(int64_t, int64_t)>& progress) {
  ICEF_RETURN_IF_ERROR(options.Validate().WithContext(path.string()));
  ICEF_ASSIGN_OR_RETURN(std::unique_ptr<VideoDecoder> decoder, VideoDecoder::Open(path));
  if (options.every == 0 && options.max_frames > 0) return ReadSpread(*decoder, options.max_frames, progress);
  const int64_t total = decoder->info().frame_count_estimate;
  std::vector<VideoFrame> frames;
  for (;;) {
    ICEF_ASSIGN_OR_RETURN(bool more, decoder->Next());
    if (!more) break;
    const int64_t i = decoder->index();
    if (options.every <= 1 || i % options.every == 0) {
      ICEF_ASSIGN_OR_RETURN(Rgb8Frame rgb, decoder->CurrentRgb());
      frames.push_back(VideoFrame{rgb.ToImage(), i, decoder->time_s()});
    }
    if (progress) progress(i + 1, total);
    if (options.max_frames > 0 && frames.size() >= size_t(options.max_frames)) break;
  }
  return frames;
}

bool LooksLikeVideo(const fs::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  for (const char* known : {".mp4", ".mov", ".mkv", ".avi", ".webm", ".m4v"})
    if (ext == known) return true;
  return false;
}

}  // namespace icef
