// The visual hull of the training masks as a hard prior on the occupancy grid (few-shot NeRFs
// otherwise fill space that no training ray constrains with floaters). A cell is carved when
//  - some training view sees the cell's centre inside its image and no pixel of the cell's
//    projected footprint (plus a margin, clipped to the image) is foreground (alpha >= threshold),
//    or
//  - no training view sees any of it (nothing there is ever supervised: novel views then render
//    background there rather than whatever the initial field holds).
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
