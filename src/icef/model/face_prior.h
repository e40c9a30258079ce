// The face-model prior P of DESIGN.md §2.1 as a DeformationPrior: the fitted face model's warp
// carried into the dataset's world frame, P(x, beta) = S^-1 W(S x, beta).
#pragma once

#include <memory>

#include "icef/core/status.h"
#include "icef/field/deformation_prior.h"
#include "icef/model/model_setup.h"

namespace icef {

// Errors: the setup has no face-model fit (its expression space is not the face model's).
Result<std::unique_ptr<DeformationPrior>> MakeFacePrior(const ModelSetup& setup);

}  // namespace icef
