// `icef track DATASET --keep-cameras --out NEW` (DESIGN.md §8): an existing dataset (NerFace's
// 76-D Face2Face vectors, instant-ngp, any other expression space) re-expressed in the face model's
// expression space, so the prior-guided methods apply to it. Its cameras, images, aabb, background
// and test tiers stay; the face model is fitted to dlib's landmarks of every frame (detected anew:
// a dataset's own landmarks_2d may follow another convention) with one head_from_world similarity
// shared by all frames (track_fit.h); each frame gets the fitted expression weights, dlib's 2D
// landmarks and the fitted model's 3D landmarks (world frame).
#pragma once

#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "icef/core/parallel.h"
#include "icef/core/status.h"
#include "icef/data/dataset.h"
#include "icef/io/json_util.h"
#include "icef/track/track_fit.h"

namespace icef::track {

struct RetrackOptions {
  bool skip_bad = false;  // drop frames without a face instead of stopping
  std::filesystem::path predictor_path;  // dlib's shape predictor; empty: the Debian default
  TrackFitOptions fit;
  Status Validate() const { return fit.Validate(); }
  std::string ToString() const;
};

struct RetrackResult {
  Dataset dataset;                   // the source dataset re-expressed (root: the source's)
  std::vector<std::string> skipped;  // "train[3] images/...: no face found"
  std::vector<std::string> frame_names;  // per fitted frame, in fit order: "train[0] images/..."
  TrackFit fit;
};

// Errors: a frame without a face (unless skip_bad) naming it, a fit that fails.
Result<RetrackResult> RetrackDataset(const Dataset& source, const RetrackOptions& options, const Executor& executor,
                                     const std::function<void(const std::string&)>& log = nullptr);

// Per frame: name, landmark residual, expression; plus the similarity and the shape.
Json RetrackReportJson(const RetrackResult& result);

// Writes the re-expressed dataset into out_dir (which must not exist or be empty): the transforms
// files, a copy of every image they reference, track/report.json. Built in a temporary sibling
// directory and renamed into place.
Status WriteRetrackedDataset(const RetrackResult& result, const std::filesystem::path& out_dir);

}  // namespace icef::track
