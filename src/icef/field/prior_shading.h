// Expression shading from the face model (docs/design.md §2.1; docs/face_model.md "Shading"): the light
// on a surface that an expression turns, which no warp of a static canonical field can show.
//
// A canonical field's colours carry the light of the canonical (neutral) surface. Where an
// expression turns the surface (an opened jaw, puffed cheeks, raised brows) the light on it changes:
// on validation identity 101 that is most of the moderate tier's change at the scale of the features
// (docs/results/expr_gain_probe). The face-model prior knows both orientations: n_can, the neutral
// face model's normal at the canonical point P(x, beta) of an observation point x, and n_obs, that
// normal carried back through the warp (the normal at x of the surface P makes of the neutral face;
// DeformationPrior::Normals). With the subject's light v (world frame: ambient 1 plus a
// Lambertian key light of strength |v| along v / |v|; fitted to the training images before training,
// model/prior_light.h), each sample's colour is scaled by
//
//     s = (1 + max(0, n_obs . v)) / (1 + max(0, n_can . v)).
//
// s = 1 wherever the expression leaves the surface's orientation as it is (the neutral face, the
// skull) and wherever the prior gives no normal (n = 0), so the canonical field still never sees the
// expression, and the shading changes no identity. s depends on the prior alone, so it has no
// parameters: the backward pass scales the colour's gradient by s.
#pragma once

#include <algorithm>
#include <cstdint>

#include "icef/core/parallel.h"
#include "icef/math/types.h"

namespace icef {

// The shading ratio s of one sample.
template <typename T>
T PriorShadeRatio(const T* n_obs, const T* n_can, const Vec3f& v) {
  const T lo = n_obs[0] * T(v[0]) + n_obs[1] * T(v[1]) + n_obs[2] * T(v[2]);
  const T lc = n_can[0] * T(v[0]) + n_can[1] * T(v[1]) + n_can[2] * T(v[2]);
  return (T(1) + std::max(T(0), lo)) / (T(1) + std::max(T(0), lc));
}

// rgb [n, 3] *= s per sample; shade [n] receives s (the backward pass multiplies the gradient of the
// shaded colour by it).
void ApplyPriorShading(const Executor& executor, int64_t n, const float* n_obs, const float* n_can,
                       const Vec3f& light, float* rgb, float* shade);

}  // namespace icef
