// Writes the generated part of the fuzzers' seed corpora (run once; the output is committed):
//   OUT/checkpoint/tiny_model.icef   a valid checkpoint of a tiny AvatarModel (SaveCheckpoint)
//   OUT/image/{grey,rgb,rgba}_4x4.png, rgb_1x1.png, rgb_8x8.jpg
// Usage: icef_fuzz_make_seeds OUT_DIR
#include <stb_image_write.h>

#include <cstdint>
#include <filesystem>
#include <iostream>
#include <vector>

#include "icef/io/atomic_file.h"
#include "icef/io/image.h"
#include "icef/model/model_test_util.h"
#include "icef/train/model_io.h"

int main(int argc, char** argv) {
  if (argc != 2) {
    std::cerr << "usage: icef_fuzz_make_seeds OUT_DIR\n";
    return 1;
  }
  namespace fs = std::filesystem;
  const fs::path out = argv[1];
  fs::create_directories(out / "checkpoint");
  fs::create_directories(out / "image");
  const icef::Executor executor(1);
  icef::RunConfig config;
  config.model = icef::testing_model::TinyModelConfig("icef");
  config.train.steps = 3;
  auto model = icef::AvatarModel::Create(config.model, icef::testing_model::TinySetup(), executor);
  if (!model.ok()) {
    std::cerr << model.status().message() << "\n";
    return 1;
  }
  icef::TrainerState state;
  state.step = 3;
  state.elapsed_seconds = 0.5;
  state.log = {"{\"step\":1}", "{\"step\":2}"};
  icef::Status s = icef::SaveCheckpoint(out / "checkpoint/tiny_model.icef", config, **model, nullptr, state);
  for (const auto& [name, w, h, c] :
       {std::tuple{"grey_4x4.png", 4, 4, 1}, std::tuple{"rgb_4x4.png", 4, 4, 3},
        std::tuple{"rgba_4x4.png", 4, 4, 4}, std::tuple{"rgb_1x1.png", 1, 1, 3}}) {
    icef::Image im(w, h, c);
    for (size_t i = 0; i < im.pixels.size(); ++i) im.pixels[i] = float(i % 5) / 4.f;
    if (s.ok()) s = icef::WritePng(out / "image" / name, im);
  }
  std::vector<uint8_t> rgb(8 * 8 * 3);
  for (size_t i = 0; i < rgb.size(); ++i) rgb[i] = uint8_t(i * 29 % 256);
  if (s.ok() && !stbi_write_jpg((out / "image/rgb_8x8.jpg").c_str(), 8, 8, 3, rgb.data(), 90))
    s = icef::Status::Error("cannot write rgb_8x8.jpg");
  if (!s.ok()) {
    std::cerr << s.message() << "\n";
    return 1;
  }
  return 0;
}
