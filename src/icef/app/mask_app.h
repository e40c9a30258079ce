// `icef mask DATASET --out DIR [--frame I]`: shows the expression-region mask M(x) so a user can
// check it before training.
//  - mask_overlay_frame<I>.png: training image I with M overlaid in red. Each pixel shows the
//    maximum of M along its ray inside the dataset aabb (a maximum-intensity projection: the
//    renderer's alpha is not available before training), so a pixel is red when its ray passes
//    through a mouth, eye or brow region. Landmarks are drawn on top: green for the 36 expression
//    landmarks (brows, eyes, mouth), blue for the others.
//  - mask_projection_frame<I>.png: the same projection as a grey image (white = 1).
//  - fit_frame<I>.png: when the dataset is in the face model's expression space, the face model
//    fitted to the training landmarks (what the *-prior methods stand on), outlined in yellow over
//    training image I; the fit's residual is printed.
//  - mask_slice_{xy,xz,yz}.png: M on axis-aligned planes through the landmark centroid, covering
//    the aabb (xy: x right, y up; xz: x right, z up; yz: z right, y up), heat-coloured.
#pragma once

#include <filesystem>
#include <ostream>

#include "icef/core/parallel.h"
#include "icef/core/status.h"

namespace icef {

struct MaskAppOptions {
  std::filesystem::path dataset;  // dataset directory (holding transforms_train.json)
  std::filesystem::path out;      // output directory for the PNGs (created if missing)
  int frame = 0;                  // training frame to overlay the mask on

  // Errors name the option; --frame is checked against the dataset by RunMask.
  Status Validate() const;
};

// Writes the PNGs above into options.out and prints the mask summary and each path on `out`.
Status RunMask(const MaskAppOptions& options, const Executor& executor, std::ostream& out);

}  // namespace icef
