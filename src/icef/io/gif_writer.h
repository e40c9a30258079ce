// Animated GIFs (giflib) for render sequences: each frame quantised to its own 256-colour palette,
// looping forever, written atomically.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "icef/core/status.h"
#include "icef/io/image.h"

namespace icef {

// frames: RGB (or grey / RGBA, alpha ignored) images of one size; delay in 1/100 s per frame.
Result<std::string> EncodeGif(const std::vector<Image>& frames, int delay_centiseconds);
Status WriteGif(const std::filesystem::path& path, const std::vector<Image>& frames, int delay_centiseconds);

}  // namespace icef
