// Image regions from a frame's 2D landmarks (iBUG 68, pixel coordinates with centres at +0.5):
// the expression region that icef eval scores expressions in (docs/evaluation.md) and that
// training can draw extra rays from (train.region_rays), and the filled hull of all landmarks.
#pragma once

#include <vector>

#include "icef/io/image.h"
#include "icef/math/types.h"

namespace icef {

// The iBUG-68 indices of brows, eyes and mouth (17-26, 36-67).
const std::vector<int>& ExpressionLandmarkIndices();

// Default dilation of the expression region in pixels for an image `width` wide: 3 px at 128, scaled.
int DefaultRegionDilation(int width);

// 1-channel mask (1 inside, 0 outside): the pixels whose centres lie within `dilation` pixels of
// the 2D convex hull of the brow, eye and mouth landmarks of `frame_landmarks`, united with the
// same of `neutral_landmarks` (may be empty). Non-finite landmarks are skipped.
Image ExpressionRegion(int width, int height, const std::vector<Vec2f>& frame_landmarks,
                       const std::vector<Vec2f>& neutral_landmarks, int dilation);

// 1-channel mask of the pixels whose centres lie in or on the filled 2D convex hull of all finite
// landmarks. Points outside the image still shape the hull, which the image then clips. Fewer
// than three non-collinear points: an empty mask.
Image LandmarkHullRegion(int width, int height, const std::vector<Vec2f>& landmarks);

}  // namespace icef
