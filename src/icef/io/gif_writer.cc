#include "icef/io/gif_writer.h"

#include <gif_lib.h>

#include <algorithm>
#include <cmath>

#include "icef/io/atomic_file.h"

namespace icef {

namespace {
int AppendToString(GifFileType* gif, const GifByteType* data, int size) {
  static_cast<std::string*>(gif->UserData)->append(reinterpret_cast<const char*>(data), size);
  return size;
}
GifByteType ToByte(float v) {
  return static_cast<GifByteType>(std::lround(std::clamp(std::isfinite(v) ? v : 0.f, 0.f, 1.f) * 255.f));
}
}  // namespace

Result<std::string> EncodeGif(const std::vector<Image>& frames, int delay_centiseconds) {
  if (frames.empty()) return Status::Error("gif: no frames");
  const int w = frames[0].width, h = frames[0].height;
  for (const Image& f : frames)
    if (f.width != w || f.height != h || f.empty()) return Status::Error("gif: frames differ in size");
  std::string out;
  int error = 0;
  GifFileType* gif = EGifOpen(&out, AppendToString, &error);
  if (!gif) return Status::Error(std::string("gif: ") + GifErrorString(error));
  auto fail = [&](const char* what) {
    int close_error = 0;
    EGifCloseFile(gif, &close_error);
    return Status::Error(std::string("gif: ") + what + ": " + GifErrorString(gif->Error));
  };
  EGifSetGifVersion(gif, true);
  if (EGifPutScreenDesc(gif, w, h, 8, 0, nullptr) == GIF_ERROR) return fail("screen descriptor");
  // NETSCAPE2.0 application extension: loop forever.
  const unsigned char netscape[] = {'N', 'E', 'T', 'S', 'C', 'A', 'P', 'E', '2', '.', '0'};
  const unsigned char loop[] = {1, 0, 0};
  if (EGifPutExtensionLeader(gif, APPLICATION_EXT_FUNC_CODE) == GIF_ERROR ||
      EGifPutExtensionBlock(gif, sizeof netscape, netscape) == GIF_ERROR ||
      EGifPutExtensionBlock(gif, sizeof loop, loop) == GIF_ERROR || EGifPutExtensionTrailer(gif) == GIF_ERROR)
    return fail("loop extension");
  const size_t n = size_t(w) * h;
  std::vector<GifByteType> r(n), g(n), b(n), indices(n);
  std::vector<GifColorType> palette(256);
  for (const Image& f : frames) {
    for (size_t p = 0; p < n; ++p) {
      const Vec3f c = f.Rgb(int(p % w), int(p / w));
      r[p] = ToByte(c.x()), g[p] = ToByte(c.y()), b[p] = ToByte(c.z());
    }
    int palette_size = 256;
    if (GifQuantizeBuffer(w, h, &palette_size, r.data(), g.data(), b.data(), indices.data(),
                          palette.data()) == GIF_ERROR)
      return fail("quantize");
    ColorMapObject* map = GifMakeMapObject(256, palette.data());
    GraphicsControlBlock gcb{};
    gcb.DisposalMode = DISPOSE_BACKGROUND;
    gcb.DelayTime = delay_centiseconds;
    gcb.TransparentColor = NO_TRANSPARENT_COLOR;
    GifByteType ext[4];
    const size_t len = EGifGCBToExtension(&gcb, ext);
    bool ok = EGifPutExtension(gif, GRAPHICS_EXT_FUNC_CODE, int(len), ext) != GIF_ERROR &&
              EGifPutImageDesc(gif, 0, 0, w, h, false, map) != GIF_ERROR;
    for (int y = 0; ok && y < h; ++y) ok = EGifPutLine(gif, indices.data() + size_t(y) * w, w) != GIF_ERROR;
    GifFreeMapObject(map);
    if (!ok) return fail("frame");
  }
  if (EGifCloseFile(gif, &error) == GIF_ERROR)
    return Status::Error(std::string("gif: ") + GifErrorString(error));
  return out;
}

Status WriteGif(const std::filesystem::path& path, const std::vector<Image>& frames, int delay_centiseconds) {
  auto bytes = EncodeGif(frames, delay_centiseconds);
  if (!bytes.ok()) return bytes.status().WithContext(path.string());
  return WriteFileAtomic(path, *bytes);
}

}  // namespace icef
