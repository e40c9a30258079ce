// The light of the prior shading (field/prior_shading.h), fitted to the training images through the
// fitted face model before training starts.
//
// Each training pixel whose ray hits the face model's skin (at the frame's expression, facing the
// camera, inside the image's alpha) gives a surface normal n (world frame) and a colour c. The fit
// solves, by robust nonlinear least squares (Ceres, Huber loss),
//
//     c ≈ rho · (1 + max(0, n · v))      rho: one skin albedo (RGB), v: the light
//
// from several starting lights, and keeps the best. Skin varies in colour, so the fit explains only
// the shading the whole face shares; the learned field keeps the rest. Measured against the known
// light of synthetic heads in prior_light_test.cc.
#pragma once

#include "icef/core/parallel.h"
#include "icef/core/status.h"
#include "icef/data/dataset.h"
#include "icef/face/face_fit.h"
#include "icef/math/types.h"
#include "icef/model/model_setup.h"

namespace icef {

struct PriorLightFit {
  Vec3f light = Vec3f::Zero();   // v, world frame
  Vec3f albedo = Vec3f::Zero();  // rho
  int pixels = 0;                // skin pixels used
  double rms = 0;                // RMS colour residual (per RGB value)
  std::string BriefReport() const;
};

// Errors: no training frame, an unreadable image, fewer than 100 face-skin pixels (icef train then
// trains without the prior shading and says so).
Result<PriorLightFit> FitPriorLight(const Dataset& dataset, const face::FaceFit& fit,
                                    const Executor& executor);
// The same through ICT-FaceKit's fit (model/ict_prior.h): the posed mesh's face skin, its
// interpolated vertex normals. Deterministic.
Result<PriorLightFit> FitPriorLight(const Dataset& dataset, const IctFaceFit& fit);

}  // namespace icef
