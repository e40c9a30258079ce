// Depth targets from the fitted face model (train.lambda_depth_prior): for each chosen training
// pixel (train.depth_prior_region: the expression region of TrainingData's region pixels, or the
// eyes alone), where the centre ray through it meets the fitted face model's surface at that frame's
// expression (the fit's shape and expression style, head_from_world carrying the ray into the head
// frame). The loss (model/losses.h, L_depth) pulls each such ray's compositing-weighted depth
// towards it. Built to test whether five views pin the depth of a one-pixel feature (the lid
// margin on the eyeball) down too poorly; measured on the validation identities, it does not move
// the eyes, so it is off by default (docs/results/near_tier_variants).
#pragma once

#include <vector>

#include "icef/core/parallel.h"
#include "icef/data/dataset.h"
#include "icef/face/face_fit.h"
#include "icef/train/training_data.h"

namespace icef {

// [data.num_pixels()] ray parameters t (world units along the pixel-centre ray), NaN outside
// `pixels` (global indices) and where the ray misses the fitted surface. expressions[k] is frame
// k's weights in the face model's order (negative values act as 0). Deterministic for any executor.
std::vector<float> FaceModelDepthTargets(const face::FaceFit& fit, const TrainingData& data,
                                         const std::vector<std::vector<float>>& expressions,
                                         const std::vector<int64_t>& pixels, const Executor& executor);

// The training pixels of the eyes: each eye's 2D landmark hull (iBUG 36-41, 42-47) of each frame
// with landmarks, dilated as the expression region (DefaultRegionDilation). Global pixel indices.
std::vector<int64_t> EyePixels(const Dataset& dataset, const TrainingData& data);

}  // namespace icef
