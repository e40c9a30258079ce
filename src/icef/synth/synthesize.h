// `icef synth`: a dataset in the docs/design.md §4 format rendered from the procedural head of one
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

// The scene axes `icef synth --diverse` draws per identity seed, each from its own stream
// Rng(seed, "synth.scene.<axis>") so that pinning one leaves the others' draws unchanged. An axis
// not drawn keeps the classic studio values of SynthOptions (the datasets of every committed
// report): one key light, a light-to-mid skin palette, the head centred in the box at scale 1.
// The main value of each axis (skin tone, key azimuth, head scale, head size in the image, yaw
// spread) is spread over consecutive seeds (SpreadUnit), so six consecutive seeds span it.
struct SceneAxes {
  bool skin = false;        // very light to very dark skin, lips/brows/hair to match (identity.h)
  bool lighting = false;    // key direction and strength, fill ratio, a second light, specular sheen
  bool placement = false;   // the head's scale and offset inside the dataset's aabb
  bool camera = false;      // camera distance and focal length (the head's size in the image)
  bool views = false;       // view spread: largest yaw 15-45 degrees, largest pitch 5-20
  bool resolution = false;  // image resolution, 128 up to SynthOptions::max_drawn_resolution
  bool detail = false;      // denser fine albedo detail: pores, wrinkles, stubble (identity.h)

  static SceneAxes All();
  bool Any() const;
  bool operator==(const SceneAxes&) const = default;
  // "skin,lighting,..." of the drawn axes ("none" when none is).
  std::string ToString() const;
  // The axis names in order.
  static const std::vector<std::string>& Names();
  // Sets the named axis (one of Names()) to `value`; an error names the unknown axis.
  Status Set(const std::string& name, bool value);
};

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
  // Tier thresholds on delta: near = (0, near_threshold], moderate = (near_threshold, far_threshold], far
  // above.
  double near_threshold = 0.35;
  double far_threshold = 0.8;
  // Camera distance from the head centre (head units; the head is ~0.75 tall).
  double camera_distance = 3.5;
  // Focal length in pixels divided by the resolution (3.6: the head fills ~80% of the height).
  double focal_scale = 3.6;
  // Largest |yaw| and |pitch| of the training views, degrees.
  double max_yaw_deg = 35.0;
  double max_pitch_deg = 15.0;
  // The head's placement in the world (dataset) frame: x_world = head_scale * x_head +
  // head_offset. The dataset's aabb stays [-1, 1]^3; Validate() requires the head inside it.
  double head_scale = 1.0;
  Vec3d head_offset = Vec3d::Zero();
  // Ground-truth renderer settings.
  RenderOptions render;
  // Axes drawn per identity seed (ResolveScene); drawn values replace the fields above.
  SceneAxes vary;
  // Largest resolution the resolution axis draws (from 128, 160, 192, 256, 320, 384, 448, 512).
  int max_drawn_resolution = 512;

  Status Validate() const;
  std::string ToString() const;
};

// A novel or observed test expression with its distance to the training set.
struct TestExpression {
  std::vector<float> beta;  // [face::kNumExpressions]
  double delta = 0;         // min_k ||beta - beta_k||_2
  Tier tier = Tier::kObserved;
};

// The options with every axis of `vary` drawn for identity_seed (lighting, placement, camera,
// views, resolution; skin and detail are identity fields, drawn by SynthIdentity). Pure function.
SynthOptions ResolveScene(const SynthOptions& options);

// The subject a dataset is rendered with: IdentityParams::FromSeed(identity_seed), with the
// generic expression style when generic_style is set, and the skin and detail axes drawn when
// `vary` asks for them.
IdentityParams SynthIdentity(const SynthOptions& options);

// The file SynthesizeDataset writes beside the transforms that records the scene: the drawn axes
// and their values (lighting, placement, camera, views, resolution, skin, detail).
inline constexpr char kSceneInfoFile[] = "scene.json";
Json SceneInfoJson(const SynthOptions& resolved, const IdentityParams& identity);

// The file SynthesizeDataset writes beside the transforms, and its contents: the seed, the
// identity's expression style (every ExpressionStyle field) and its StyleGap at weight 1.
inline constexpr char kStyleInfoFile[] = "style.json";
Json StyleInfoJson(const SynthOptions& options, const IdentityParams& identity, const face::StyleGap& gap);

// Everything drawn for a dataset before rendering (cheap; used by the tests and the writer).
// PlanSynthesis resolves the scene first (ResolveScene); cameras are in the head frame, which the
// dataset's world frame is after WorldFromHead.
struct SynthPlan {
  SynthOptions resolved;  // ResolveScene(options)
  Intrinsics intrinsics;
  std::vector<Camera> train_cameras;                  // [K]
  std::vector<std::vector<float>> train_expressions;  // [K][face::kNumExpressions]
  std::vector<Camera> test_cameras;                   // [V]
  std::vector<TestExpression> test_expressions;       // K observed, then near, moderate, far
};
Result<SynthPlan> PlanSynthesis(const SynthOptions& options);

// min_k ||beta - beta_k||_2 over the training expressions (infinity when there are none).
double ExpressionDelta(const std::vector<float>& beta, const std::vector<std::vector<float>>& train);
// observed for delta == 0, near for (0, t0], moderate for (t0, t1], far above t1.
Tier TierForDelta(double delta, double near_threshold, double far_threshold);

// A camera at `distance` from the origin at (yaw, pitch) degrees looking at the origin (yaw 0,
// pitch 0 looks at the face along -z).
Camera OrbitCamera(const Intrinsics& intrinsics, double distance, double yaw_deg, double pitch_deg);

// The camera of the dataset's world frame that sees the head at options.head_scale/head_offset
// exactly as `head_camera` sees it at scale 1 in the head frame (same rotation and intrinsics).
Camera WorldFromHead(const SynthOptions& options, const Camera& head_camera);

// Number of images SynthesizeDataset writes (the progress total): K + V + (K + 3 n) V.
int64_t SynthImageCount(const SynthOptions& options);

// Renders and writes the dataset (images/ + transforms_{train,test}.json via SaveDataset, and
// kStyleInfoFile). The written Dataset is returned through `written` and the subject's style gap
// (face::MeasureStyleGap at weight 1) through `style_gap` when non-null. progress may be null.
Status SynthesizeDataset(const SynthOptions& options, const Executor& executor,
                         ProgressBar* progress = nullptr, Dataset* written = nullptr,
                         face::StyleGap* style_gap = nullptr);

}  // namespace icef::synth
