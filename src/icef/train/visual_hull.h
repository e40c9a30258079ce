// The visual hull of the training masks as a hard prior on the occupancy grid (few-shot NeRFs
// otherwise fill space that no training ray constrains with floaters): a cell is carved when some
// training view sees the cell's whole projected footprint (plus a margin) inside the image and no
// pixel of it is foreground (alpha >= threshold). Views that see the cell only partly, or not at
// all, do not carve it, so the hull is conservative.
#pragma once

#include <vector>

#include "icef/core/parallel.h"
#include "icef/io/image.h"
#include "icef/math/camera.h"
#include "icef/math/ray.h"

namespace icef {

struct VisualHullOptions {
  int margin_px = 2;            // footprint dilation in pixels
  float alpha_threshold = 0.5f;  // alpha at or above this is foreground
};

// alphas: one 1-channel image per camera (same size as the camera). Returns [R^3] flags, index
// (z R + y) R + x, 1 = may be occupied.
std::vector<uint8_t> VisualHullCells(const Aabb& aabb, int resolution, const std::vector<Camera>& cameras,
                                     const std::vector<Image>& alphas, const VisualHullOptions& options,
                                     const Executor& executor);

}  // namespace icef
