// A contact sheet of a dataset: one row of training frames, one of the neutral test views, and one
// row per test tier (observed, near, moderate, far) showing each test expression once (views taken
// in turn), every tile composited over the background and labelled (stb_easy_font).
#pragma once

#include <string>
#include <vector>

#include "icef/core/status.h"
#include "icef/data/dataset.h"
#include "icef/io/image.h"

namespace icef::synth {

struct ContactSheetOptions {
  // Tile size in pixels (frames are box-filtered down or repeated up to it).
  int tile = 96;
  // Most tiles per row (extra frames of a row are left out).
  int max_columns = 8;
  // Draw labels under the tiles.
  bool labels = true;

  Status Validate() const;
  std::string ToString() const;
};

// Loads the frames' images (errors name the file) and tiles them into an RGB image.
Result<Image> MakeContactSheet(const Dataset& dataset,
                               const ContactSheetOptions& options = ContactSheetOptions());

// One row per dataset of its training frames (the first tile labelled with the dataset's directory
// name): several subjects side by side, e.g. the scenes of `icef synth --diverse`.
Result<Image> MakeTrainingSheet(const std::vector<Dataset>& datasets,
                                const ContactSheetOptions& options = ContactSheetOptions());

// Draws `text` (ASCII, stb_easy_font's ~6x7 pixel font) with its top-left corner at (x, y).
void DrawText(Image& image, int x, int y, const std::string& text, const Vec3f& color);

}  // namespace icef::synth
