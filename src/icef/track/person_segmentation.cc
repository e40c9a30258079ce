#include "icef/track/person_segmentation.h"

#include <algorithm>

#include "icef/infer/tfjs_graph.h"

namespace icef::track {

struct PersonSegmenter::Impl {
  infer::TfjsGraph graph;
  std::string output;
};

Result<PersonSegmenter> PersonSegmenter::Load(const std::filesystem::path& dir) {
  ICEF_ASSIGN_OR_RETURN(infer::TfjsGraph graph,
                        infer::LoadInstalledGraph(dir, "ICEF_SELFIE_MODEL", kDefaultSelfieDir, "selfie.json",
                                                  {kInputSize, kInputSize, 3}, "segmentation model",
                                                  "--segmentation none tracks without it"));
  auto impl = std::make_shared<Impl>();
  impl->graph = std::move(graph);
  impl->output = "activation_10";  // the sigmoid of the last transposed convolution
  PersonSegmenter segmenter;
  segmenter.impl_ = std::move(impl);
  return segmenter;
}

Result<Image> PersonSegmenter::Run(const Image& image) const {
  if (image.width < 1 || image.height < 1 || image.channels < 3)
    return Status::Error("person segmentation: expected an RGB image, got " + std::to_string(image.width) +
                         " x " + std::to_string(image.height) + " x " + std::to_string(image.channels));
  infer::Tensor3 rgb(image.height, image.width, 3);
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x)
      for (int c = 0; c < 3; ++c) rgb.At(y, x, c) = std::clamp(image.At(x, y, c), 0.f, 1.f);
  const infer::Tensor3 input = infer::ResizeBilinear(rgb, kInputSize, kInputSize, false, true);
  ICEF_ASSIGN_OR_RETURN(auto outputs, impl_->graph.Run(input, {impl_->output}));
  const infer::Tensor3 p =
      infer::ResizeBilinear(outputs.at(impl_->output), image.height, image.width, false, true);
  Image out(image.width, image.height, 1);
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x) out.At(x, y, 0) = std::clamp(p.At(y, x, 0), 0.f, 1.f);
  return out;
}

}  // namespace icef::track
