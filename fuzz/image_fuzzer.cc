// libFuzzer target: the image reader (ReadImageInfo, ReadImage) on arbitrary bytes. Every input
// must give an image whose pixel count matches its size and whose values lie in [0, 1], or an
// error naming the file; never a crash, leak or undefined behaviour.
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "fuzz/fuzz_util.h"
#include "icef/io/image.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::filesystem::path path = icef::fuzz::ScratchDir() / "input.png";
  icef::fuzz::WriteBytes(path, std::string_view(reinterpret_cast<const char*>(data), size));
  const icef::Result<icef::ImageInfo> info = icef::ReadImageInfo(path);
  const icef::Result<icef::Image> image = icef::ReadImage(path);
  if (!image.ok()) {
    if (image.status().message().find(path.string()) == std::string::npos)
      std::abort();  // error must name the file
    return 0;
  }
  const icef::Image& im = *image;
  if (!info.ok() || info->width != im.width || info->height != im.height) std::abort();
  if (im.channels != 1 && im.channels != 3 && im.channels != 4) std::abort();
  if (im.pixels.size() != size_t(im.width) * im.height * im.channels) std::abort();
  for (float v : im.pixels)
    if (!(v >= 0.f && v <= 1.f)) std::abort();
  return 0;
}
