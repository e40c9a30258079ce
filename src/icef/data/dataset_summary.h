// What `icef info` prints: a dataset's shape at a glance (frames, resolutions, intrinsics,
// expressions, landmarks, tiers, expression distances), as text or JSON.
#pragma once

#include <array>
#include <optional>
#include <string>
#include <vector>

#include "icef/core/parallel.h"
#include "icef/data/dataset.h"
#include "icef/io/json_util.h"

namespace icef {

struct Range {
  double min = 0;
  double max = 0;
};

struct SplitSummary {
  std::string name;  // "train", "test" or "val"
  int num_frames = 0;
  int with_landmarks_2d = 0;         // frames that carry 68 2D landmarks
  int with_landmarks_3d = 0;         // frames that carry 68 3D landmarks
  int with_neutral = 0;              // frames with a neutral_file_path
  std::array<int, 4> tier_counts{};  // indexed by Tier
  int without_tier = 0;
  std::optional<Range> delta;  // over frames that carry delta
};

struct DatasetSummary {
  std::string root;
  std::vector<SplitSummary> splits;         // train, test, val (always all three)
  std::vector<std::string> resolutions;     // distinct "WxH", in order of first appearance
  std::optional<Range> fl_x, fl_y, cx, cy;  // over all frames (absent without frames)
  Aabb aabb;
  int expression_dim = 0;
  std::vector<std::string> expression_names;
  Vec3f background = Vec3f::Ones();
  std::optional<std::string> background_file_path;
  std::optional<std::array<double, 2>> tier_thresholds;
  // min / max of ||beta_i - beta_j|| over pairs of training frames (needs 2+ frames).
  std::optional<Range> train_expression_distance;

  const SplitSummary& Split(const std::string& name) const;
  std::string ToString() const;  // multi-line, human readable
  Json ToJson() const;
};

// Summarises a loaded dataset. The pairwise distances run in parallel on `executor`; the result
// does not depend on the thread count.
DatasetSummary SummarizeDataset(const Dataset& dataset, const Executor& executor);

}  // namespace icef
