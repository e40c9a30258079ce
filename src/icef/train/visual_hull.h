// The visual hull of the training masks as a hard prior on the occupancy grid (few-shot NeRFs
// otherwise fill space that no training ray constrains with floaters). A cell is carved when
//  - some training view sees the cell's centre inside its image and no pixel of the cell's
//    projected footprint (plus a margin, clipped to the image) is foreground (alpha >= threshold),
//    or
//  - fewer than min_views training views see its centre: space that only one or two views
//    constrain is where few-shot floaters live (a blob in front of one camera can paint that
//    view's pixels without any other view objecting), and novel views render background there
//    rather than whatever the field put in it.
#pragma once

#include <vector>

#include "icef/core/parallel.h"
#include "icef/io/image.h"
#include "icef/math/camera.h"
#include "icef/math/ray.h"

namespace icef {

struct VisualHullOptions {
  int margin_px = 2;             // footprint dilation in pixels
  float alpha_threshold = 0.5f;  // alpha at or above this is foreground
  int min_views = 1;             // cells whose centre fewer views see are carved
};

// alphas: one 1-channel image per camera (same size as the camera). Returns [R^3] flags, index
// (z R + y) R + x, 1 = may be occupied.
std::vector<uint8_t> VisualHullCells(const Aabb& aabb, int resolution, const std::vector<Camera>& cameras,
                                     const std::vector<Image>& alphas, const VisualHullOptions& options,
                                     const Executor& executor);

}  // namespace icef
