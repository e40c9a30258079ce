#include "icef/video/libav_util.h"

extern "C" {
#include <libavutil/display.h>
}

#include <cmath>
#include <cstring>
#include <mutex>

namespace icef::libav {

void OutputDeleter::operator()(AVFormatContext* p) const {
  if (p->pb && !(p->oformat->flags & AVFMT_NOFILE)) avio_closep(&p->pb);
  avformat_free_context(p);
}

std::string ErrorText(int code) {
  char text[AV_ERROR_MAX_STRING_SIZE] = {};
  if (av_strerror(code, text, sizeof text) < 0) return "libav error " + std::to_string(code);
  return text;
}

void SilenceLogs() {
  static std::once_flag once;
  std::call_once(once, [] { av_log_set_level(AV_LOG_QUIET); });
}

// The stream's display matrix (3x3 int32), or nullptr. The API moved into AVCodecParameters in
// FFmpeg 6.1 (libavformat 60.15) and the old one is gone in FFmpeg 7 (libavformat 61).
static const int32_t* DisplayMatrix(const AVStream& stream) {
#if LIBAVFORMAT_VERSION_MAJOR >= 61
  const AVPacketSideData* sd = av_packet_side_data_get(
      stream.codecpar->coded_side_data, stream.codecpar->nb_coded_side_data, AV_PKT_DATA_DISPLAYMATRIX);
  if (sd == nullptr || sd->size < 9 * sizeof(int32_t)) return nullptr;
  return reinterpret_cast<const int32_t*>(sd->data);
#else
  size_t size = 0;
  const uint8_t* data = av_stream_get_side_data(&stream, AV_PKT_DATA_DISPLAYMATRIX, &size);
  if (data == nullptr || size < 9 * sizeof(int32_t)) return nullptr;
  return reinterpret_cast<const int32_t*>(data);
#endif
}

int StreamRotation(const AVStream& stream) {
  const int32_t* matrix = DisplayMatrix(stream);
  if (matrix == nullptr) return 0;
  // Counter-clockwise degrees (NaN if degenerate); FFmpeg's autorotate turns the frames clockwise by -ccw.
  const double ccw = av_display_rotation_get(matrix);
  if (!std::isfinite(ccw)) return 0;
  const int quarter = static_cast<int>(std::lround(-ccw / 90.0));
  return ((quarter % 4) + 4) % 4 * 90;
}

bool SetStreamRotation(AVStream& stream, int degrees) {
  int32_t matrix[9];
  av_display_rotation_set(matrix, degrees);  // takes clockwise degrees: get(set(a)) == -a
#if LIBAVFORMAT_VERSION_MAJOR >= 61
  AVPacketSideData* sd =
      av_packet_side_data_new(&stream.codecpar->coded_side_data, &stream.codecpar->nb_coded_side_data,
                              AV_PKT_DATA_DISPLAYMATRIX, sizeof matrix, 0);
  if (sd == nullptr) return false;
  std::memcpy(sd->data, matrix, sizeof matrix);
#else
  uint8_t* data = av_stream_new_side_data(&stream, AV_PKT_DATA_DISPLAYMATRIX, sizeof matrix);
  if (data == nullptr) return false;
  std::memcpy(data, matrix, sizeof matrix);
#endif
  return true;
}

}  // namespace icef::libav
