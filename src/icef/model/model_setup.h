// What a model takes from its training dataset and keeps for its whole life (saved in every
// checkpoint, so rendering and evaluation need only the model directory): the aabb, the
// expression space, the observed training expressions (for the confidence kappa and beta_n), the
// 68 landmarks the region mask is built from, the background colour, and (for the methods on the
// face-model prior) the face model fitted to the training frames.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "icef/core/parallel.h"
#include "icef/data/dataset.h"
#include "icef/face/face_fit.h"
#include "icef/io/json_util.h"
#include "icef/math/camera.h"
#include "icef/math/ray.h"

namespace icef {

// ICT-FaceKit fitted to a dataset in its expression space (model/ict_prior.h: FitIctToDataset).
struct IctFaceFit {
  std::vector<float> identity;       // coefficients of the first identity modes
  face::Similarity head_from_world;  // dataset world frame -> ICT head frame (cm)
  double rms_iod = 0;                // the identity fit's landmark RMS over the training frames (IOD)
};

struct ModelSetup {
  Aabb aabb;  // world frame
  int expression_dim = 0;
  std::vector<std::string> expression_names;             // [expression_dim] or empty
  std::vector<std::vector<float>> training_expressions;  // [K][expression_dim]
  std::vector<Vec3f> mask_landmarks;                     // [68] world frame
  std::string mask_source;                               // where the landmarks came from
  Vec3f background = Vec3f::Ones();
  std::vector<Camera> training_cameras;   // [K] (renders default to their intrinsics and views)
  std::optional<face::FaceFit> face_fit;  // the fitted procedural face model (model/face_prior.h), if any
  std::optional<IctFaceFit> ict_fit;      // the fitted ICT-FaceKit model (model/ict_prior.h), if any
  std::optional<Vec3f> prior_light;       // the prior shading's light (model/prior_light.h), if fitted

  // From a loaded dataset's training split; the landmarks come from RegionMask::FromDataset's
  // rules (mean landmarks_3d, else triangulated landmarks_2d).
  static Result<ModelSetup> FromDataset(const Dataset& dataset, const Executor& executor);
  Json ToJson() const;
  static Result<ModelSetup> FromJson(const Json& json, const std::string& origin);
  // Index of a named expression coefficient, or -1.
  int ExpressionIndex(const std::string& name) const;
};

}  // namespace icef
