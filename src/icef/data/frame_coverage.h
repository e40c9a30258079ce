// Which K of many frames of one person to train on (`icef track VIDEO --frames K`, `icef bench
// --real`): the frames that cover head pose and expression best. A greedy farthest-point choice in
// a space where 15 degrees of view direction weigh as much as a whole expression weight: first the
// most frontal and neutral frame (the anchor of the canonical space), then each time the frame
// farthest from every frame chosen so far, its distance scaled down for a blurred frame. Blinks and
// frames much blurrier than the median are taken only when too few others remain.
#pragma once

#include <string>
#include <vector>

#include "icef/math/types.h"

namespace icef {

struct Frame;

// One candidate frame.
struct CoverageCandidate {
  Vec3d view_direction = Vec3d(0, 0, 1);  // unit vector from the head's origin to the camera, head frame
  std::vector<float> expression;          // the frame's expression weights (all candidates the same length)
  double sharpness = 1;                   // relative to the median candidate (1 = the median)
  bool blink = false;                     // an eye closes (taken only when too few other frames remain)
};

struct CoverageOptions {
  double degrees_per_unit = 15;  // view-direction degrees that weigh as much as 1.0 of one expression weight
  double min_sharpness = 0.5;    // frames below this relative sharpness are taken only when needed
  bool allow_blink = false;      // blinks are ordinary candidates
};

// Indices of k candidates (k <= candidates.size()) in the order chosen; deterministic (ties go to
// the lower index). The first k' of a choice of k are the choice of k' < k.
std::vector<int> ChooseCoverageFrames(const std::vector<CoverageCandidate>& candidates, int k,
                                      const CoverageOptions& options = {});

// The candidate of a dataset frame: its camera's direction from the head (world) origin and its
// expression; sharpness 1, no blink (`blink_weight_names` are the expression names whose weight
// above 0.5 marks a blink, e.g. the eye-close weights).
CoverageCandidate CandidateOfFrame(const Frame& frame, const std::vector<std::string>& expression_names);

}  // namespace icef
