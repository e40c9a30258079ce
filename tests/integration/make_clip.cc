// icef_make_clip OUT.mp4 FPS FRAME.png...: the test suite's own encoder (video/video_writer.h), so
// that the video tests decode a clip the tests made themselves.
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "icef/io/image.h"
#include "icef/video/video_writer.h"

int main(int argc, char** argv) {
  if (argc < 4) {
    std::fprintf(stderr, "usage: icef_make_clip OUT.mp4 FPS FRAME.png...\n");
    return 2;
  }
  std::vector<icef::Image> frames;
  for (int i = 3; i < argc; ++i) {
    icef::Result<icef::Image> image = icef::ReadImage(argv[i]);
    if (!image.ok()) {
      std::fprintf(stderr, "%s\n", image.status().message().c_str());
      return 1;
    }
    frames.push_back(image->HasAlpha() ? icef::CompositeOver(*image, icef::Vec3f::Ones()) : *image);
  }
  icef::VideoWriteOptions options;
  options.fps = std::atof(argv[2]);
  const icef::Status status = icef::WriteVideo(argv[1], frames, options);
  if (!status.ok()) {
    std::fprintf(stderr, "%s\n", status.message().c_str());
    return 1;
  }
  return 0;
}
