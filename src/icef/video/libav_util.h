// Internal to the video module (the public headers do not include libav): owners for libav
// objects (unique_ptr with custom deleters), the text of a libav error code, and the switch that
// keeps libav's own log lines off the terminal.
#pragma once

extern "C" {
#include <libavcodec/avcodec.h>
#include <libavformat/avformat.h>
#include <libavutil/pixdesc.h>
#include <libswscale/swscale.h>
}

#include <memory>
#include <string>

namespace icef::libav {

struct InputDeleter {
  void operator()(AVFormatContext* p) const { avformat_close_input(&p); }
};
// An output context: closes its file (if open) and frees it; the file itself is left to the caller.
struct OutputDeleter {
  void operator()(AVFormatContext* p) const;
};
struct CodecDeleter {
  void operator()(AVCodecContext* p) const { avcodec_free_context(&p); }
};
struct FrameDeleter {
  void operator()(AVFrame* p) const { av_frame_free(&p); }
};
struct PacketDeleter {
  void operator()(AVPacket* p) const { av_packet_free(&p); }
};
struct SwsDeleter {
  void operator()(SwsContext* p) const { sws_freeContext(p); }
};

using InputPtr = std::unique_ptr<AVFormatContext, InputDeleter>;
using OutputPtr = std::unique_ptr<AVFormatContext, OutputDeleter>;
using CodecPtr = std::unique_ptr<AVCodecContext, CodecDeleter>;
using FramePtr = std::unique_ptr<AVFrame, FrameDeleter>;
using PacketPtr = std::unique_ptr<AVPacket, PacketDeleter>;
using SwsPtr = std::unique_ptr<SwsContext, SwsDeleter>;

// av_strerror's text for a libav return code, e.g. "Invalid data found when processing input".
std::string ErrorText(int code);

// Sets libav's log level to quiet (once per process): our Status lines carry the reasons.
void SilenceLogs();

// The display-rotation tag of a stream as clockwise degrees, rounded to 0, 90, 180 or 270.
int StreamRotation(const AVStream& stream);
// Tags `stream` (before the header is written) to be shown turned clockwise by `degrees`.
bool SetStreamRotation(AVStream& stream, int degrees);

}  // namespace icef::libav
