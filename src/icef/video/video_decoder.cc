#include "icef/video/video_decoder.h"

#include <algorithm>
#include <cmath>
#include <system_error>

namespace icef {

namespace fs = std::filesystem;

Image Rgb8Frame::ToImage() const {
  Image image(width, height, 3);
  for (size_t i = 0; i < rgb.size(); ++i) image.pixels[i] = rgb[i] * (1.f / 255.f);
  return image;
}

Rgb8Frame RotateClockwise(const Rgb8Frame& frame, int degrees) {
  if (degrees == 0) return frame;
  const int w = frame.width, h = frame.height;
  Rgb8Frame out;
  out.width = degrees == 180 ? w : h;
  out.height = degrees == 180 ? h : w;
  out.rgb.resize(frame.rgb.size());
  for (int y = 0; y < out.height; ++y) {
    for (int x = 0; x < out.width; ++x) {
      int sx = x, sy = y;  // the source pixel shown at (x, y)
      if (degrees == 90) sx = y, sy = h - 1 - x;
      if (degrees == 180) sx = w - 1 - x, sy = h - 1 - y;
      if (degrees == 270) sx = w - 1 - y, sy = x;
      for (int c = 0; c < 3; ++c)
        out.rgb[(size_t(y) * out.width + x) * 3 + c] = frame.rgb[(size_t(sy) * w + sx) * 3 + c];
    }
  }
  return out;
}

Status VideoDecoder::Error(const std::string& what) const {
  return Status::Error(path_.string() + ": " + what);
}

Result<std::unique_ptr<VideoDecoder>> VideoDecoder::Open(const fs::path& path) {
  libav::SilenceLogs();
  std::unique_ptr<VideoDecoder> d(new VideoDecoder());
  d->path_ = path;
  std::error_code ec;
  if (!fs::exists(path, ec)) return d->Error("file not found");
  if (fs::is_directory(path, ec)) return d->Error("is a directory, expected a video file");

  // "file:" keeps a name with a colon from being taken for a protocol.
  AVFormatContext* raw = nullptr;
  int r = avformat_open_input(&raw, ("file:" + path.string()).c_str(), nullptr, nullptr);
  if (r < 0) return d->Error("not a video file the decoder can read (" + libav::ErrorText(r) + ")");
  d->format_.reset(raw);
  r = avformat_find_stream_info(raw, nullptr);
  if (r < 0)
    return d->Error("truncated or corrupt video: cannot read the stream parameters (" + libav::ErrorText(r) +
                    ")");

  const AVCodec* decoder = nullptr;
  r = av_find_best_stream(raw, AVMEDIA_TYPE_VIDEO, -1, -1, &decoder, 0);
  if (r == AVERROR_DECODER_NOT_FOUND) {
    for (unsigned i = 0; i < raw->nb_streams; ++i) {
      const AVCodecID id = raw->streams[i]->codecpar->codec_id;
      if (raw->streams[i]->codecpar->codec_type != AVMEDIA_TYPE_VIDEO) continue;
      if (id == AV_CODEC_ID_NONE)
        return d->Error("truncated or corrupt video: its video codec is unrecognisable");
      return d->Error(std::string("no decoder for its video codec (") + avcodec_get_name(id) + ")");
    }
  }
  if (r < 0 || decoder == nullptr) return d->Error("no video stream");
  d->stream_index_ = r;
  for (unsigned i = 0; i < raw->nb_streams; ++i)
    if (int(i) != r) raw->streams[i]->discard = AVDISCARD_ALL;  // demux only the video stream
  AVStream* stream = raw->streams[r];

  d->codec_.reset(avcodec_alloc_context3(decoder));
  d->frame_.reset(av_frame_alloc());
  d->packet_.reset(av_packet_alloc());
  if (!d->codec_ || !d->frame_ || !d->packet_) return d->Error("out of memory opening the decoder");
  r = avcodec_parameters_to_context(d->codec_.get(), stream->codecpar);
  if (r < 0)
    return d->Error("cannot set up the " + std::string(decoder->name) + " decoder (" + libav::ErrorText(r) +
                    ")");
  d->codec_->thread_count = 0;  // libav chooses
  r = avcodec_open2(d->codec_.get(), decoder, nullptr);
  if (r < 0)
    return d->Error("cannot open the " + std::string(decoder->name) + " decoder (" + libav::ErrorText(r) +
                    ")");

  VideoInfo& info = d->info_;
  info.rotation = libav::StreamRotation(*stream);
  const bool swap = info.rotation == 90 || info.rotation == 270;
  info.width = swap ? stream->codecpar->height : stream->codecpar->width;
  info.height = swap ? stream->codecpar->width : stream->codecpar->height;
  const AVRational rate = av_guess_frame_rate(raw, stream, nullptr);
  info.fps = rate.num > 0 && rate.den > 0 ? av_q2d(rate) : 0;
  d->time_base_ = av_q2d(stream->time_base);
  d->start_pts_ = stream->start_time != AV_NOPTS_VALUE ? stream->start_time : 0;
  if (stream->duration != AV_NOPTS_VALUE && stream->duration > 0) {
    info.duration_s = stream->duration * d->time_base_;
  } else if (raw->duration != AV_NOPTS_VALUE && raw->duration > 0) {
    info.duration_s = double(raw->duration) / AV_TIME_BASE;
  }
  if (stream->nb_frames > 0) {
    info.frame_count_estimate = stream->nb_frames;
  } else if (info.duration_s > 0 && info.fps > 0) {
    info.frame_count_estimate = std::llround(info.duration_s * info.fps);
  }
  info.codec = avcodec_get_name(stream->codecpar->codec_id);
  return d;
}

Result<bool> VideoDecoder::Finish() {
  ended_ = true;
  if (index_ >= 0) return false;
  std::string why = "truncated or corrupt video: no frame could be decoded";
  if (last_error_ != 0) why += " (" + libav::ErrorText(last_error_) + ")";
  return Error(why);
}

Result<bool> VideoDecoder::Next() {
  if (ended_) return false;
  AVCodecContext* codec = codec_.get();
  for (;;) {
    int r = avcodec_receive_frame(codec, frame_.get());
    if (r == 0) {
      ++index_;
      return true;
    }
    if (r == AVERROR_EOF) return Finish();
    if (r != AVERROR(EAGAIN)) last_error_ = r;  // a damaged frame: go on with the next packet
    if (flushing_) return Finish();             // drained (or the decoder failed while draining)
    r = av_read_frame(format_.get(), packet_.get());
    if (r < 0) {  // end of file, or the file breaks off: drain what the decoder holds
      if (r != AVERROR_EOF) last_error_ = r;
      flushing_ = true;
      avcodec_send_packet(codec, nullptr);
      continue;
    }
    if (packet_->stream_index != stream_index_) {
      av_packet_unref(packet_.get());
      continue;
    }
    r = avcodec_send_packet(codec, packet_.get());
    av_packet_unref(packet_.get());
    if (r < 0 && r != AVERROR(EAGAIN)) last_error_ = r;  // a damaged packet is skipped, as ffmpeg does
  }
}

double VideoDecoder::time_s() const {
  const int64_t pts = frame_->best_effort_timestamp;
  if (pts == AV_NOPTS_VALUE) return info_.fps > 0 ? index_ / info_.fps : 0.0;
  return (pts - start_pts_) * time_base_;
}

Result<Rgb8Frame> VideoDecoder::CurrentRgb() {
  const AVFrame& f = *frame_;
  if (index_ < 0 || f.width <= 0 || f.height <= 0) return Error("no decoded frame to convert");
  const int key[5] = {f.width, f.height, f.format, int(f.colorspace), int(f.color_range)};
  if (!sws_ || !std::equal(key, key + 5, sws_key_)) {
    sws_.reset(sws_getContext(f.width, f.height, AVPixelFormat(f.format), f.width, f.height, AV_PIX_FMT_RGB24,
                              SWS_BICUBIC | SWS_ACCURATE_RND | SWS_FULL_CHR_H_INT, nullptr, nullptr,
                              nullptr));
    if (!sws_) {
      const char* name = av_get_pix_fmt_name(AVPixelFormat(f.format));
      return Error("frame " + std::to_string(index_) + ": cannot convert pixel format " +
                   (name ? name : "unknown") + " to RGB");
    }
    // The frame's own YUV matrix and range (BT.709 and full-range phone videos), to full-range RGB.
    const int space = f.colorspace == AVCOL_SPC_UNSPECIFIED ? SWS_CS_DEFAULT : int(f.colorspace);
    int* inv_table = nullptr;
    int* table = nullptr;
    int src_range = 0, dst_range = 0, brightness = 0, contrast = 0, saturation = 0;
    if (sws_getColorspaceDetails(sws_.get(), &inv_table, &src_range, &table, &dst_range, &brightness,
                                 &contrast, &saturation) >= 0) {
      if (f.color_range == AVCOL_RANGE_JPEG) src_range = 1;
      sws_setColorspaceDetails(sws_.get(), sws_getCoefficients(space), src_range, table, 1, brightness,
                               contrast, saturation);
    }
    std::copy(key, key + 5, sws_key_);
  }
  Rgb8Frame rgb;
  rgb.width = f.width;
  rgb.height = f.height;
  rgb.rgb.resize(size_t(f.width) * f.height * 3);
  uint8_t* dst[4] = {rgb.rgb.data(), nullptr, nullptr, nullptr};
  const int dst_stride[4] = {f.width * 3, 0, 0, 0};
  if (sws_scale(sws_.get(), f.data, f.linesize, 0, f.height, dst, dst_stride) != f.height)
    return Error("frame " + std::to_string(index_) + ": conversion to RGB failed");
  return RotateClockwise(rgb, info_.rotation);
}

}  // namespace icef
