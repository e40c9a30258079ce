// `icef synth`: a dataset in the DESIGN.md §4 format rendered from the procedural head of one
// identity. Training frames: K distinct views (yaw within ±max_yaw, pitch within ±max_pitch), each
// with its own moderate random expression. Test frames: V held-out views, at every training
// expression (tier "observed", delta = 0) and at novel expressions in the near, moderate and far
// tiers (delta = min_k ||beta - beta_k||_2 is computed and the tier derived from it), plus the
// neutral render of every test view (neutral_file_path). Every frame carries 68 landmarks (2D with
// visibility, 3D). The subject performs the expressions in its own style (IdentityParams::style);
// style.json beside the transforms records that style and its gap to the generic one (it is not
// part of the dataset format, and nothing that trains or evaluates reads it). The output is a
// pure function of the options (same seed, same bytes).
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "icef/core/parallel.h"
#include "icef/core/progress.h"
#include "icef/core/status.h"
#include "icef/data/dataset.h"
#include "icef/face/style_gap.h"
#include "icef/io/json_util.h"
#include "icef/math/camera.h"
#include "icef/synth/ground_truth_renderer.h"

namespace icef::synth {

struct SynthOptions {
  // Output directory (created; existing files of the same names are replaced).
  std::filesystem::path out_dir;
  // Identity seed: face shape, expression style, albedo, and the views and expressions drawn.
  uint64_t identity_seed = 1;
  // Render with the generic expression style instead of the identity's own (the face model's
  // expressions exactly, as before styles existed).
  bool generic_style = false;
  // Number of training frames K.
  int num_train = 5;
  // Image width and height in pixels.
  int resolution = 128;
  // Held-out test views V (each test expression is rendered at all of them).
  int test_views = 3;
  // Novel test expressions per tier (near, moderate, far).
  int novel_per_tier = 2;
  // Tier thresholds on delta: near = (0, near_threshold], moderate = (near_threshold, far_threshold], far above.
  double near_threshold = 0.35;
  double far_threshold = 0.8;
  // Camera distance from the head centre (head units; the head is ~0.75 tall).
  double camera_distance = 3.5;
  // Focal length in pixels divided by the resolution (3.6: the head fills ~80% of the height).
  double focal_scale = 3.6;
  // Largest |yaw| and |pitch| of the training views, degrees.
  double max_yaw_deg = 35.0;
  double max_pitch_deg = 15.0;
  // Ground-truth renderer settings.
  RenderOptions render;

  Status Validate() const;
  std::string ToString() const;
};

// A novel or observed test expression with its distance to the training set.
struct TestExpression {
  std::vector<float> beta;  // [face::kNumExpressions]
  double delta = 0;         // min_k ||beta - beta_k||_2
  Tier tier = Tier::kObserved;
};

// The subject a dataset is rendered with: IdentityParams::FromSeed(identity_seed), with the
// generic expression style when generic_style is set.
IdentityParams SynthIdentity(const SynthOptions& options);

// The file SynthesizeDataset writes beside the transforms, and its contents: the seed, the
// identity's expression style (every ExpressionStyle field) and its StyleGap at weight 1.
inline constexpr char kStyleInfoFile[] = "style.json";
Json StyleInfoJson(const SynthOptions& options, const IdentityParams& identity, const face::StyleGap& gap);

// Everything drawn for a dataset before rendering (cheap; used by the tests and the writer).
struct SynthPlan {
  Intrinsics intrinsics;
  std::vector<Camera> train_cameras;                 // [K]
  std::vector<std::vector<float>> train_expressions;  // [K][face::kNumExpressions]
  std::vector<Camera> test_cameras;                  // [V]
  std::vector<TestExpression> test_expressions;      // K observed, then near, moderate, far
};
Result<SynthPlan> PlanSynthesis(const SynthOptions& options);

// min_k ||beta - beta_k||_2 over the training expressions (infinity when there are none).
double ExpressionDelta(const std::vector<float>& beta, const std::vector<std::vector<float>>& train);
// observed for delta == 0, near for (0, t0], moderate for (t0, t1], far above t1.
Tier TierForDelta(double delta, double near_threshold, double far_threshold);

// A camera at `distance` from the origin at (yaw, pitch) degrees looking at the origin (yaw 0,
// pitch 0 looks at the face along -z).
Camera OrbitCamera(const Intrinsics& intrinsics, double distance, double yaw_deg, double pitch_deg);

// Number of images SynthesizeDataset writes (the progress total): K + V + (K + 3 n) V.
int64_t SynthImageCount(const SynthOptions& options);

// Renders and writes the dataset (images/ + transforms_{train,test}.json via SaveDataset, and
// kStyleInfoFile). The written Dataset is returned through `written` and the subject's style gap
// (face::MeasureStyleGap at weight 1) through `style_gap` when non-null. progress may be null.
Status SynthesizeDataset(const SynthOptions& options, const Executor& executor, ProgressBar* progress = nullptr,
                         Dataset* written = nullptr, face::StyleGap* style_gap = nullptr);

}  // namespace icef::synth
