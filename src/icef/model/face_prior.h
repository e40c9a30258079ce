// The face-model prior P of docs/design.md §2.1 as a DeformationPrior: the fitted face model's warp
// carried into the dataset's world frame, P(x, beta) = S^-1 W(S x, beta) with S = head_from_world,
// and its mouth cavity, in the fit's expression style (the generic one unless the style was fitted
// to the training frames' landmarks: model.prior_style).
#pragma once

#include <memory>

#include "icef/core/status.h"
#include "icef/data/dataset.h"
#include "icef/face/face_fit.h"
#include "icef/field/deformation_prior.h"
#include "icef/model/model_setup.h"

namespace icef {

// OK when the expression names are the face model's, in its order; else an error that says how to
// re-express the dataset.
Status CheckFaceModelExpressions(const std::vector<std::string>& expression_names, const std::string& origin);

// Fits the face model to the dataset's training frames (landmarks_3d, else landmarks_2d and the
// cameras); options.fit_style fits the subject's expression style too. Errors: another expression space,
// frames without landmarks, a failed fit.
Result<face::FaceFit> FitFaceModelToDataset(const Dataset& dataset, const face::FaceFitOptions& options = {});

// The prior of setup.ict_fit (IctPrior) when there is one, else of setup.face_fit (the procedural
// model's). Errors: no face-model fit, another expression space.
Result<std::unique_ptr<DeformationPrior>> MakeFacePrior(const ModelSetup& setup);

}  // namespace icef
