// Test landmarks whose expression-region points (brows, eyes, mouth) span a box.
#pragma once

#include <vector>

#include "icef/data/landmark_region.h"
#include "icef/math/types.h"

namespace icef::testing {

// 68 landmarks whose brow/eye/mouth points span the box [x0, x1] x [y0, y1]; the others far away.
inline std::vector<Vec2f> BoxLandmarks(float x0, float y0, float x1, float y1) {
  std::vector<Vec2f> l(68, Vec2f(1000.f, 1000.f));
  const Vec2f corners[4] = {{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}};
  int j = 0;
  for (int i : ExpressionLandmarkIndices()) l[i] = corners[j++ % 4];
  return l;
}

}  // namespace icef::testing
