// libFuzzer target: the dataset loader. The input is the text of transforms_train.json in a
// scratch dataset directory that also holds valid images (images/train_000.png 4x4 RGB,
// images/rgba.png 4x4 RGBA, images/grey.png 4x4 grey, images/wide.png 8x4 RGB and the NerFace
// background bg/00050.png 4x4). LoadDataset must return a dataset or an error that names a file;
// never crash, leak or hit undefined behaviour. A loaded dataset's frames must be consistent.
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "fuzz/fuzz_util.h"
#include "icef/data/dataset.h"
#include "icef/io/image.h"

namespace {

void WriteImage(const std::filesystem::path& path, int w, int h, int c) {
  icef::Image im(w, h, c);
  for (size_t i = 0; i < im.pixels.size(); ++i) im.pixels[i] = float(i % 7) / 6.f;
  std::filesystem::create_directories(path.parent_path());
  icef::fuzz::WriteBytes(path, icef::EncodePng(im));
}

const std::filesystem::path& DatasetDir() {
  static const std::filesystem::path dir = [] {
    const std::filesystem::path d = icef::fuzz::ScratchDir() / "dataset";
    WriteImage(d / "images/train_000.png", 4, 4, 3);
    WriteImage(d / "images/rgba.png", 4, 4, 4);
    WriteImage(d / "images/grey.png", 4, 4, 1);
    WriteImage(d / "images/wide.png", 8, 4, 3);
    WriteImage(d / "bg/00050.png", 4, 4, 3);
    return d;
  }();
  return dir;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::filesystem::path& dir = DatasetDir();
  icef::fuzz::WriteBytes(dir / "transforms_train.json",
                         std::string_view(reinterpret_cast<const char*>(data), size));
  const icef::Result<icef::Dataset> dataset = icef::LoadDataset(dir);
  if (!dataset.ok()) {
    if (dataset.status().message().find(dir.string()) == std::string::npos) std::abort();  // must name a file
    return 0;
  }
  for (const icef::Frame& frame : dataset->train) {
    if (int(frame.expression.size()) != dataset->expression_dim) std::abort();
    if (frame.landmarks_2d && frame.landmarks_2d->size() != size_t(icef::kNumLandmarks)) std::abort();
    if (frame.landmarks_3d && frame.landmarks_3d->size() != size_t(icef::kNumLandmarks)) std::abort();
  }
  (void)dataset->ToString();
  return 0;
}
