#include "icef/video/video_writer.h"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <system_error>

extern "C" {
#include <libavutil/opt.h>
}

#include "icef/video/libav_util.h"

namespace icef {

namespace fs = std::filesystem;

Status VideoWriteOptions::Validate() const {
  if (!(fps > 0 && fps <= 1000)) return Status::Error("fps must be in (0, 1000], got " + std::to_string(fps));
  if (crf < 0 || crf > 51) return Status::Error("crf must be in [0, 51], got " + std::to_string(crf));
  if (codec != "auto" && codec != "libx264" && codec != "mpeg4")
    return Status::Error("codec must be \"auto\", \"libx264\" or \"mpeg4\", got \"" + codec + "\"");
  if (rotation != 0 && rotation != 90 && rotation != 180 && rotation != 270)
    return Status::Error("rotation must be 0, 90, 180 or 270, got " + std::to_string(rotation));
  return Status::Ok();
}

std::string VideoWriteOptions::ToString() const {
  std::ostringstream os;
  os << "VideoWriteOptions(fps=" << fps << ", crf=" << crf << ", codec=" << codec << ", rotation=" << rotation
     << ")";
  return os.str();
}

struct VideoWriter::State {
  fs::path out;  // the destination
  fs::path tmp;  // the file being written (empty once renamed into place)
  int width = 0;
  int height = 0;
  libav::OutputPtr format;
  libav::CodecPtr codec;
  AVStream* stream = nullptr;  // owned by `format`
  libav::FramePtr frame;       // yuv420p, reused for each frame
  libav::PacketPtr packet;
  libav::SwsPtr sws;         // rgb24 -> yuv420p
  std::vector<uint8_t> rgb;  // [height, width, 3], the frame being added
  int64_t next_pts = 0;      // in codec time-base units: the frame number

  ~State() {
    sws.reset();
    codec.reset();
    format.reset();  // closes the file
    std::error_code ec;
    if (!tmp.empty()) fs::remove(tmp, ec);
  }

  Status Error(const std::string& what) const { return Status::Error(out.string() + ": " + what); }

  // Sends `f` (nullptr: end of stream) to the encoder and writes every packet it returns.
  Status Encode(const AVFrame* f) {
    int r = avcodec_send_frame(codec.get(), f);
    if (r < 0) return Error("encoding failed (" + libav::ErrorText(r) + ")");
    for (;;) {
      r = avcodec_receive_packet(codec.get(), packet.get());
      if (r == AVERROR(EAGAIN) || r == AVERROR_EOF) return Status::Ok();
      if (r < 0) return Error("encoding failed (" + libav::ErrorText(r) + ")");
      av_packet_rescale_ts(packet.get(), codec->time_base, stream->time_base);
      packet->stream_index = stream->index;
      r = av_interleaved_write_frame(format.get(), packet.get());  // takes the packet's data
      if (r < 0) return Error("write failed (" + libav::ErrorText(r) + ")");
    }
  }
};

VideoWriter::VideoWriter() = default;
VideoWriter::~VideoWriter() = default;

Status VideoWriter::Open(const fs::path& out, int width, int height, const VideoWriteOptions& options) {
  libav::SilenceLogs();
  if (state_) return Status::Error(out.string() + ": the writer is already open for " + state_->out.string());
  ICEF_RETURN_IF_ERROR(options.Validate().WithContext(out.string()));
  if (width <= 0 || width % 2 != 0)
    return Status::Error(out.string() + ": width must be even and positive for yuv420p video, got " +
                         std::to_string(width));
  if (height <= 0 || height % 2 != 0)
    return Status::Error(out.string() + ": height must be even and positive for yuv420p video, got " +
                         std::to_string(height));
  const fs::path dir = out.has_parent_path() ? out.parent_path() : fs::path(".");
  std::error_code ec;
  if (!fs::is_directory(dir, ec))
    return Status::Error(out.string() + ": directory " + dir.string() + " does not exist");

  auto s = std::make_unique<State>();
  s->out = out;
  s->width = width;
  s->height = height;
  char suffix[48];
  std::snprintf(suffix, sizeof suffix, ".tmp-%ld-%llx", long(::getpid()),
                static_cast<unsigned long long>(reinterpret_cast<uintptr_t>(s.get()) & 0xffffffffffULL));
  const fs::path tmp = dir / (out.filename().string() + suffix);

  const AVCodec* encoder = nullptr;
  if (options.codec != "mpeg4") encoder = avcodec_find_encoder_by_name("libx264");
  if (encoder == nullptr && options.codec == "libx264") return s->Error("libavcodec has no libx264 encoder");
  if (encoder == nullptr) encoder = avcodec_find_encoder_by_name("mpeg4");
  if (encoder == nullptr) return s->Error("libavcodec has neither the libx264 nor the mpeg4 encoder");
  const bool x264 = std::string(encoder->name) == "libx264";

  AVFormatContext* raw = nullptr;
  int r = avformat_alloc_output_context2(&raw, nullptr, "mp4", tmp.c_str());
  if (r < 0 || raw == nullptr) return s->Error("cannot set up the MP4 muxer (" + libav::ErrorText(r) + ")");
  s->format.reset(raw);
  s->stream = avformat_new_stream(raw, nullptr);
  s->codec.reset(avcodec_alloc_context3(encoder));
  s->frame.reset(av_frame_alloc());
  s->packet.reset(av_packet_alloc());
  if (!s->stream || !s->codec || !s->frame || !s->packet)
    return s->Error("out of memory setting up the encoder");

  AVCodecContext* c = s->codec.get();
  const AVRational rate = av_d2q(options.fps, 65535);  // mpeg4 allows time-base denominators up to 65535
  c->width = width;
  c->height = height;
  c->pix_fmt = AV_PIX_FMT_YUV420P;
  c->framerate = rate;
  c->time_base = av_inv_q(rate);
  c->color_range = AVCOL_RANGE_MPEG;    // what libswscale writes for yuv420p
  c->colorspace = AVCOL_SPC_SMPTE170M;  // BT.601, libswscale's default matrix
  c->thread_count = 0;
  if (raw->oformat->flags & AVFMT_GLOBALHEADER) c->flags |= AV_CODEC_FLAG_GLOBAL_HEADER;
  if (x264) {
    av_opt_set(c->priv_data, "crf", std::to_string(options.crf).c_str(), 0);
  } else {  // CRF 0..51 onto MPEG-4's q-scale 1..31 (CRF 20 -> q 4)
    c->flags |= AV_CODEC_FLAG_QSCALE;
    c->global_quality = FF_QP2LAMBDA * std::clamp(int(std::lround(options.crf / 5.0)), 1, 31);
  }
  r = avcodec_open2(c, encoder, nullptr);
  if (r < 0)
    return s->Error("cannot open the " + std::string(encoder->name) + " encoder (" + libav::ErrorText(r) +
                    ")");
  r = avcodec_parameters_from_context(s->stream->codecpar, c);
  if (r < 0) return s->Error("cannot set up the video stream (" + libav::ErrorText(r) + ")");
  s->stream->time_base = c->time_base;
  s->stream->avg_frame_rate = rate;
  if (options.rotation != 0 && !libav::SetStreamRotation(*s->stream, options.rotation))
    return s->Error("out of memory tagging the rotation");

  s->frame->format = c->pix_fmt;
  s->frame->width = width;
  s->frame->height = height;
  r = av_frame_get_buffer(s->frame.get(), 0);
  if (r < 0) return s->Error("out of memory for a frame (" + libav::ErrorText(r) + ")");
  s->sws.reset(sws_getContext(width, height, AV_PIX_FMT_RGB24, width, height, AV_PIX_FMT_YUV420P,
                              SWS_BICUBIC | SWS_ACCURATE_RND, nullptr, nullptr, nullptr));
  if (!s->sws) return s->Error("cannot set up the RGB to yuv420p conversion");
  s->rgb.resize(size_t(width) * height * 3);

  r = avio_open(&raw->pb, ("file:" + tmp.string()).c_str(), AVIO_FLAG_WRITE);
  if (r < 0)
    return s->Error("cannot create temporary file " + tmp.string() + " (" + libav::ErrorText(r) + ")");
  s->tmp = tmp;  // from here on the destructor removes it
  r = avformat_write_header(raw, nullptr);
  if (r < 0) return s->Error("cannot write the MP4 header (" + libav::ErrorText(r) + ")");
  encoder_ = encoder->name;
  state_ = std::move(s);
  return Status::Ok();
}

Status VideoWriter::Add(const Image& image) {
  if (!state_)
    return Status::Error("VideoWriter::Add: the writer is not open (never opened, closed, or failed)");
  State& s = *state_;
  if (image.width != s.width || image.height != s.height) {
    const Status error =
        s.Error("frame " + std::to_string(s.next_pts) + " is " + std::to_string(image.width) + "x" +
                std::to_string(image.height) + ", the video is " + std::to_string(s.width) + "x" +
                std::to_string(s.height));
    state_.reset();
    return error;
  }
  if (image.channels < 1 || image.channels > 4 ||
      image.pixels.size() != size_t(image.width) * image.height * image.channels) {
    const Status error = s.Error("frame " + std::to_string(s.next_pts) + " has " +
                                 std::to_string(image.channels) + " channels, expected 1, 3 or 4");
    state_.reset();
    return error;
  }
  const size_t n = size_t(s.width) * s.height;
  for (size_t p = 0; p < n; ++p) {
    for (int c = 0; c < 3; ++c) {
      const float v = image.pixels[p * image.channels + (image.channels < 3 ? 0 : c)];
      s.rgb[p * 3 + c] = uint8_t(v > 0.f ? (v < 1.f ? v : 1.f) * 255.f + 0.5f : 0.f);  // NaN -> 0
    }
  }
  int r = av_frame_make_writable(s.frame.get());
  if (r < 0) {
    const Status error = s.Error("out of memory for a frame (" + libav::ErrorText(r) + ")");
    state_.reset();
    return error;
  }
  const uint8_t* src[4] = {s.rgb.data(), nullptr, nullptr, nullptr};
  const int src_stride[4] = {s.width * 3, 0, 0, 0};
  sws_scale(s.sws.get(), src, src_stride, 0, s.height, s.frame->data, s.frame->linesize);
  s.frame->pts = s.next_pts++;
  Status status = s.Encode(s.frame.get());
  if (!status.ok()) state_.reset();
  return status;
}

Status VideoWriter::Close() {
  if (!state_)
    return Status::Error("VideoWriter::Close: the writer is not open (never opened, closed, or failed)");
  std::unique_ptr<State> s = std::move(state_);  // removes the temporary on every early return
  if (s->next_pts == 0) return s->Error("no frames were added");
  ICEF_RETURN_IF_ERROR(s->Encode(nullptr));
  int r = av_write_trailer(s->format.get());
  if (r < 0) return s->Error("cannot finish the MP4 (" + libav::ErrorText(r) + ")");
  r = avio_closep(&s->format->pb);
  if (r < 0) return s->Error("write failed (" + libav::ErrorText(r) + ")");
  const int fd = ::open(s->tmp.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0 || ::fsync(fd) != 0) {
    if (fd >= 0) ::close(fd);
    return s->Error("flush failed");
  }
  ::close(fd);
  std::error_code ec;
  fs::rename(s->tmp, s->out, ec);
  if (ec) return s->Error("rename failed: " + ec.message());
  s->tmp.clear();
  return Status::Ok();
}

Status WriteVideo(const fs::path& out, const std::vector<Image>& frames, const VideoWriteOptions& options) {
  if (frames.empty()) return Status::Error(out.string() + ": no frames to write");
  VideoWriter writer;
  ICEF_RETURN_IF_ERROR(writer.Open(out, frames[0].width, frames[0].height, options));
  for (const Image& frame : frames) ICEF_RETURN_IF_ERROR(writer.Add(frame));
  return writer.Close();
}

}  // namespace icef
